// The springs' weighted graph Laplacian, the constant matrix of projective dynamics (Liu et al.
// 2013): on n points,
//   P = d I + diag(extra) + sum_s (a c_s + b k_s) (e_a - e_b)(e_a - e_b)^T,
// one n x n matrix that acts on x, y and z alike. With d = m, a, b those of the implicit system
// A = M - a D - b K it bounds every spring's part of A from above (each spring's clamped
// Hessian is at most k_s I and its damping block at most c_s I), so P^-1 A has its eigenvalues
// in (0, 1]: the projective preconditioner of CG and the seed iterations of Newton; with
// d = m/h^2, a = 0, b = 1 and the contact weights as `extra`, it is projective's own matrix.
// The pattern (every diagonal entry and both of every spring's pair, duplicates merged) is built
// once per model and refilled in place.
#pragma once

#include <vector>

#include "solvers/system/jacobian.h"
#include "src/model.h"

namespace jello {

class SpringLaplacian {
 public:
  explicit SpringLaplacian(const Model& model);

  // P as above into `out` (given this pattern on first use); extra: n values or null.
  void form(double d, double a, double b, const double* extra, SparseMatrix& out) const;
  // The largest over the points of a C_pp / (d + b K_pp): how far the damping's diagonal
  // outweighs the rest of P's (projective's lag of the damping converges when it is small).
  double dampingRatio(double d, double a, double b) const;
  const SparseMatrix& pattern() const { return stiffness_; }
  int numPoints() const { return static_cast<int>(diagonal_.size()); }

 private:
  SparseMatrix stiffness_;       // sum k_s (...), the pattern
  std::vector<double> damping_;  // sum c_s (...), values in the same pattern
  std::vector<int> diagonal_;    // value index of each diagonal entry
};

}  // namespace jello
