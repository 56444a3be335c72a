// The projective matrix of a lattice, P = d I + sum_s (a c_s + b k_s)(e_a - e_b)(e_a - e_b)^T
// (solvers/system/spring_laplacian.h), bounded from above by a matrix that the cosine transform
// diagonalizes (solvers/linalg/cosine_solver.h), for a global step without a factor.
// Per axis, the path Laplacian L1 (free ends) is diagonal in the cosine basis, eigenvalues
// s = 2 - 2 cos(pi a/N); so is C = I - L1/2 (cos(pi a/N)). Each kind of spring's Laplacian is
// the interior's stencil with the boundary's missing neighbours put back:
//   structural  sum_axes L1                        (exact: L1 is the path's own)
//   face shear  sum_pairs 4 (I - C_i C_j)          (the two diagonals of a plane: exact inside)
//   body shear  8 (I - C_1 C_2 C_3)                (the four body diagonals)
//   bend        sum_axes 4 (I - C_i^2)             (the second neighbours: 2 - 2 cos 2a inside)
// Each bound minus the Laplacian it bounds is positive semidefinite (it adds springs to points
// outside, tied to the boundary's own: e.g. face shear's is (2I - D1) (x) L1 + L1 (x) (2I - D1),
// D1 the path's degrees), so the bound P' >= P majorizes projective's energy as P does and each
// local/global iteration with it still descends; P'^-1 P has its eigenvalues in (0.35, 1]
// (measured at N = 6 and 9, every d >= 0: the boundary's modes converge slower, the interior's
// as with P). Built only where the springs are the whole lattice, one stiffness and damping per
// kind (fits).
#pragma once

#include <Eigen/Core>
#include <array>

#include "solvers/linalg/cosine_solver.h"
#include "solvers/linalg/sparse_matrix.h"
#include "src/model.h"

namespace jello {

class SpringLaplacian;

class LatticeSpectral {
 public:
  // Whether the model's springs are its whole lattice (every offset's springs, none more), with
  // one stiffness and one damping per kind of spring.
  static bool fits(const Model& model);

  explicit LatticeSpectral(const Model& model);  // fits(model)

  int numPoints() const { return n_ * n_ * n_; }
  // The bound P' of P(d, a, b) as above; fails when it is not positive definite (d <= 0).
  // With `laplacian` (the model's), also P' - P, for the boundary's corrections.
  StepResult form(double d, double a, double b, const SpringLaplacian* laplacian = nullptr);
  // x = P'^-1 x for `columns` columns of numPoints() values, one after the other; then
  // `corrections` times x = x0 + P'^-1 (P' - P) x (x0 the first), the Neumann series of P^-1
  // (form with the laplacian first).
  void solve(double* x, int columns, int corrections = 0);

 private:
  int n_;
  std::array<double, kSpringKinds> stiffness_{}, damping_{};  // per kind (0: none)
  CosineSolver solver_;
  SparseMatrix boundary_;  // P' - P: nonzero only near the faces
  Eigen::MatrixXd first_, work_;
};

}  // namespace jello
