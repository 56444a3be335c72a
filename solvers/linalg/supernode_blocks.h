// The kept factor's columns before its dense tail (solvers/linalg/prefactored_cholesky.h), by
// CHOLMOD's supernodes: a supernode's columns share their rows below it, so its entries are
// stored as one dense block by rows (its own triangle, then the rows below, explicit zeros
// included), and the substitutions hold eight of its columns' values in registers while they
// run over the rows: an entry costs one load and one multiply-add, where the copy by single
// entries cost an index, a gathered value and the entry. The triangle of each eight columns is
// kept inverted: solving it is then a product whose eight sums do not wait for each other,
// where substituting through it made every column's value wait for the one before (the chained
// triangles were latency, not work: BM_KeptFactorSolve/copy).
#pragma once

#include <vector>

namespace jello {

// Doubles from one point's entries to the next in the substitutions' workspace: up to three
// right-hand sides and a pad, one 4-wide vector per point.
inline constexpr int kSubstitutionStride = 4;
// One point's entries of the right-hand sides (three and a pad) as one vector. Aligned like a
// double: the substitutions read them in place from arrays of doubles, whose 32-byte alignment
// nothing guarantees (a clone compiled for AVX-512 used aligned moves on them and faulted).
using SubstitutionLanes = double __attribute__((vector_size(32), aligned(8)));
static_assert(sizeof(SubstitutionLanes) == kSubstitutionStride * sizeof(double));

class SupernodeBlocks {
 public:
  // First column of each supernode, the last entry the tail's first (set before copy()).
  std::vector<int> start;

  // The blocks from L's strictly lower entries by columns (plain row indices) and the inverse
  // of its diagonal, of the n x n factor, the columns before start.back(); with samePattern,
  // only the values, into the last call's blocks, when every entry falls in them (after an
  // update of the same factor).
  void copy(int n, const std::vector<int>& colStart, const std::vector<int>& colRow,
            const std::vector<double>& colValue, const std::vector<double>& inverseDiagonal,
            bool samePattern);

  // L y = y over these columns (pushing their values into the rows after them), and L^T z = y
  // (pulling the rows' values), in place: point i's `columns` (1 to 3) entries at
  // yd + kSubstitutionStride i.
  void forward(int columns, double* yd) const;
  void backward(int columns, double* yd) const;

 private:
  // Supernode sn's columns, eight at a time; T one double or four lanes.
  template <typename T, bool Forward>
  void sweep(int sn, double* yd) const;
  // Each chunk's triangle (eight columns of a supernode and their rows) inverted into inverses_.
  void invertChunks(const std::vector<double>& inverseDiagonal);

  std::vector<int> rowStart_;    // each supernode's rows in rows_: its columns, then those below
  std::vector<int> rows_;        // offsets of the rows' entries (kSubstitutionStride x the row)
  std::vector<int> valueStart_;  // each supernode's block in values_, rows x width by rows
  std::vector<double> values_;
  std::vector<double> inverses_;  // the chunk of columns c .. c + 7's at 8 c, 8 x 8 by rows
  std::vector<int> local_;        // copy()'s work: a row's place in a block
};

}  // namespace jello
