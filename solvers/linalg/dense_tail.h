// The last supernodes of a small Cholesky factor (PrefactoredCholesky's copied factors), solved as
// one dense triangle: at 8^3, projective's M/h^2 + L ends in nearly dense columns (the last
// supernode alone has 197 columns and 40% of L's entries), which the sparse copy reads one
// entry, one index and one gathered value at a time. Here the triangle is read eight rows (or
// columns) to a vector for up to three right-hand sides at once, in panels of eight columns whose
// 8 x 8 diagonal blocks are kept inverted (their substitution becomes a product: no chain of
// dependent divisions). The right-hand sides are given side by side, `paddedWidth()` entries
// each, the padding zero.
#pragma once

#include <cstddef>
#include <vector>

struct cholmod_factor_struct;  // CHOLMOD's cholmod_factor

namespace jello {

// The entries CHOLMOD stores for supernode sn of a supernodal factor L (its lower trapezoid,
// the diagonal included).
long supernodeEntries(const cholmod_factor_struct& L, std::size_t sn);

// The inverse of a w x w lower triangle (w <= DenseTail::kPanel) by rows, row i at
// out + kPanel i: forward substitution on the identity's columns, from the entries below the
// diagonal lower(i, j) (i > j) and the diagonal diagonal(i).
template <typename Lower, typename Diagonal>
void invertLowerTriangle(int w, const Lower& lower, const Diagonal& diagonal, double* out);

class DenseTail {
 public:
  static constexpr int kPanel = 8;
  // block: the tail's width x width lower triangle by columns (as CHOLMOD lays out a
  // supernode: diagonal included, the part above it ignored).
  void copy(const double* block, int width);
  // The tail of the numeric supernodal factor L (real, double) of an n x n matrix: its last
  // supernodes, as many as pay (kTailEntryCost in dense_tail.cpp), copied as one triangle when
  // they span at least two panels. Returns the tail's first column; n (and no tail) when none.
  int copyTail(const cholmod_factor_struct& L, int n);
  void clear() { paddedWidth_ = 0; }
  int paddedWidth() const { return paddedWidth_; }
  // Solve L y = y (forward) and L' y = y (backward) in place, y holding `columns` (1 to 3)
  // right-hand sides of paddedWidth() entries one after the other.
  void forward(double* y, int columns) const;
  void backward(double* y, int columns) const;
  // Room for three right-hand sides of paddedWidth(), aligned as the copy is (the caller fills
  // it, padding included).
  double* workspace() { return data_.work; }

  // The copy, as the kernels read it (public for them; not an interface). Every array starts
  // on a 64-byte boundary, and so does every column and row (paddedWidth() doubles apart): a
  // vector of eight doubles then never straddles two cache lines.
  struct Data {
    std::vector<double> storage;
    double* byColumn = nullptr;  // strictly lower entries below each panel, by columns
    double* byRow = nullptr;     // the same entries, by rows
    // Each panel's 8 x 8 diagonal block inverted, by columns, and its transpose by columns.
    double* inverse = nullptr;
    double* inverseTransposed = nullptr;
    double* work = nullptr;
  };

 private:
  Data data_;
  int paddedWidth_ = 0;
};

template <typename Lower, typename Diagonal>
void invertLowerTriangle(int w, const Lower& lower, const Diagonal& diagonal, double* out) {
  constexpr int stride = DenseTail::kPanel;
  for (int k = 0; k < w; ++k) {  // column k
    for (int i = 0; i < w; ++i) {
      double sum = i == k ? 1.0 : 0.0;
      for (int s = 0; s < i; ++s) sum -= lower(i, s) * out[s * stride + k];
      out[i * stride + k] = sum / diagonal(i);
    }
  }
}

}  // namespace jello
