// The Jacobians of the total force: K = df/dx and D = df/dv (3n x 3n, component-major ordering
// like the state, N/m and N*s/m), assembled into sparse matrices whose pattern is built once
// and whose values are refilled in place at every state (no triplets, no re-analysis). The
// terms themselves live beside each effect's force (Model::addJacobian,
// src/effects/jacobian_blocks.h: springs, walls, plane, sphere, field); this class owns the pattern
// (every point's diagonal block and both off-diagonal blocks of every spring, which never changes
// with contact) and scatters the diagonal blocks into it. The compression clamp (on by default,
// counted) projects each spring's element Hessian onto semidefinite matrices, so M - h D - h^2 K
// stays positive definite. The field's gradient is not symmetric and is left out unless asked for
// (not for Cholesky).
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "src/model.h"

namespace jello {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct JacobianOptions {
  bool clampCompression = true;
  bool includeField = false;  // the field's gradient is not symmetric: not for Cholesky
  // The velocities (3n) friction's D is evaluated at, the one term of D that depends on v, and
  // the smooth contact's damping term of K, c vn w'(q) (null: both are left out).
  const double* velocities = nullptr;
  // Off: the other effects' diagonal blocks only (diagonalK(), diagonalD()); K() and D() keep
  // the values of the last assembly with springs (SystemOperator::fill takes the springs').
  bool includeSprings = true;
};

class JacobianAssembler {
 public:
  explicit JacobianAssembler(const Model& model);

  // Refills K and D at positions x, 3n component-major (every force but friction is linear in
  // v: friction's D, and K's smooth-contact damping term, at options.velocities).
  void assemble(const double* x, const JacobianOptions& options);

  const SparseMatrix& K() const { return K_; }
  const SparseMatrix& D() const { return D_; }
  // v^T D_f v for friction's part D_f of the last assembly's D (0 without friction): what
  // Newton's merit takes out of its damping term to weigh friction by its own potential.
  double frictionQuadratic(const double* v) const;

  // A = mass I - alpha D - beta K, written into A's values. A must have the pattern of K (use
  // pattern() to make one); the values are combined array-wise.
  void combine(double alpha, double beta, SparseMatrix& A) const;
  const SparseMatrix& pattern() const { return K_; }

  // Where the values of each spring's blocks (a,b), (b,a) (18 per spring, in the order of
  // SpringForces::springs()) and of each point's diagonal block (9 per point) are in the
  // pattern's value array: what SystemOperator gathers.
  const std::vector<int>& springSlots() const { return springSlots_; }
  const std::vector<int>& diagonalSlots() const { return diagSlots_; }

  // Every point's diagonal block of the last assembly (9 per point, row-major): of K and D.
  const std::vector<double>& diagonalK() const { return diagK_; }
  const std::vector<double>& diagonalD() const { return diagD_; }

  long lastClampCount() const { return lastClamps_; }  // springs clamped in the last assembly
  long totalClampCount() const { return totalClamps_; }

 private:
  const Model& model_;
  SparseMatrix K_, D_;
  std::vector<int> springSlots_;       // 18 per spring: value index of blocks (a,b), (b,a)
  std::vector<int> diagSlots_;         // 9 per point: value index of its diagonal block
  std::vector<double> diagK_, diagD_;  // 9 per point: diagonal blocks gathered densely
  std::vector<double> diagFriction_;   // 9 per point: friction's part of diagD_, or empty
  std::vector<int> diagonal_;          // value index of each diagonal entry (for the mass)
  long lastClamps_ = 0, totalClamps_ = 0;
};

}  // namespace jello
