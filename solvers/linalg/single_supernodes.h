// A CHOLMOD supernodal factor copied in single precision, and its substitutions: the solves of
// PrefactoredCholesky's large factors (solvers/linalg/prefactored_cholesky.h). The factor's dense
// supernodes are kept as floats, the diagonal's inverse in double; the substitutions read the
// floats (half the memory traffic of CHOLMOD's doubles: these solves are bound by it) and do
// every product and sum in double, one to three right-hand sides at once, each block of L read
// once (and each float widened once) for all of them, eight rows to a vector with AVX-512.
// BM_KeptFactorSolve/single against /cholmod and /copy compares them (solvers/README.md).
#pragma once

#include <vector>

struct cholmod_factor_struct;  // CHOLMOD's cholmod_factor

namespace jello {

class SingleSupernodes {
 public:
  // Copies the numeric supernodal factor L of an n x n matrix (real, double).
  void copy(const cholmod_factor_struct& L, int n);
  // The right-hand sides, in the factor's (permuted) order, one after the other: up to three
  // of n entries. solve() replaces them by the solutions of L L' x = y.
  double* workspace() { return data_.y.data(); }
  void solve(int columns);

  // The copy, as the substitutions read it (public for them; not an interface).
  struct Data {
    std::vector<int> first, rowStart, rows;  // supernode k: columns first[k] ..
    std::vector<long> valueStart;            // its dense column-major block in values
    std::vector<float> values;
    std::vector<double> inverseDiagonal;
    int tallest = 0;           // the most rows of a supernode
    std::vector<double> work;  // a supernode's rows per right-hand side, gathered
    std::vector<double> y;     // the permuted right-hand sides
  };

 private:
  Data data_;
  int n_ = 0;
};

}  // namespace jello
