// The Jacobians of the total force: K = df/dx and D = df/dv (3n x 3n, component-major ordering
// like the state, N/m and N*s/m), assembled into sparse matrices whose pattern is built once
// and whose values are refilled in place at every state (no triplets, no re-analysis).
//
// Springs (src/PHYSICS.md), u = unit vector along the spring, P = u u^T, alpha = 1 - L0/l:
//   Ke = -k [ P + alpha (I - P) ]   on blocks (a,a), (b,b);  -Ke on (a,b), (b,a)
//   De = -c P                        likewise
// Under compression alpha < 0 and K gains positive directions, so M - h D - h^2 K can become
// indefinite; the compression clamp replaces alpha by max(alpha, 0), which is the projection
// of the spring's element Hessian onto semidefinite matrices. It is on by default and counted.
// The x-derivative of spring damping (non-symmetric) is omitted, as Baraff & Witkin do.
// Contact (diagonal block of the point only, so the pattern never changes):
//   walls, plane:  K = -kc n n^T,  D = -dc n n^T
//   sphere:        K = -kc n n^T + kc (R/l - 1) (I - n n^T)   (the second term is the surface's
//                  curvature; positive, so the clamp drops it), D = -dc n n^T
// Force field (optional, off for the implicit solvers): K += dF/dx, the trilinear gradient.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "src/model.h"

namespace jello {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct JacobianOptions {
  bool clampCompression = true;
  bool includeField = false;  // the field's gradient is not symmetric: not for Cholesky
};

class JacobianAssembler {
 public:
  explicit JacobianAssembler(const Model& model);

  // Refills K and D at state (x, v), arrays of 3n, component-major.
  void assemble(const double* x, const double* v, const JacobianOptions& options);

  const SparseMatrix& K() const { return K_; }
  const SparseMatrix& D() const { return D_; }

  // A = mass I - alpha D - beta K, written into A's values. A must have the pattern of K (use
  // pattern() to make one); the values are combined array-wise.
  void combine(double alpha, double beta, SparseMatrix& A) const;
  const SparseMatrix& pattern() const { return K_; }

  long lastClampCount() const { return lastClamps_; }  // springs clamped in the last assembly
  long totalClampCount() const { return totalClamps_; }

 private:
  const Model& model_;
  std::vector<Spring> springs_;
  SparseMatrix K_, D_;
  std::vector<int> springSlots_;       // 18 per spring: value index of blocks (a,b), (b,a)
  std::vector<int> diagSlots_;         // 9 per point: value index of its diagonal block
  std::vector<double> diagK_, diagD_;  // 9 per point: diagonal blocks gathered densely
  std::vector<int> diagonal_;          // value index of each diagonal entry (for the mass)
  long lastClamps_ = 0, totalClamps_ = 0;
};

}  // namespace jello
