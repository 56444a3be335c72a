// The one implicit system that every implicit integrator and CVODE solve. Bound to one model
// (by its id, never its address), it holds the force Jacobians K = df/dx and D = df/dv (pattern
// built once per model; the terms come from each effect, Model::addJacobian), the system matrix
//   A = M - a D - b K
// in the same pattern, and the linear solver that factors and solves it. Every implicit method
// solves with such an A:
//   implicit-linear                        a = h,                b = h^2
//   implicit, midpoint, newmark, bdf2      a = sigma h^2/gamma,  b = theta h^2/gamma
//                                          (solvers/methods/newton_integrators.h)
//   cvode                                  a = g,                b = g^2 (the reduced Newton
//                                          matrix of its first-order system)
// so a new effect needs only its addJacobian, and a new implicit method only its a and b.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "solvers/integrator.h"
#include "solvers/linalg/linear_solver.h"
#include "solvers/system/jacobian.h"
#include "solvers/system/lattice_coarse_space.h"
#include "solvers/system/system_operator.h"

namespace jello {

class PrefactoredCholesky;
class SpringLaplacian;

class ImplicitSystem {
 public:
  // directOperator: under matrix-free CG with a preconditioner that needs no sparse A (not
  // preconditionerNeedsMatrix), A's blocks are filled straight from the springs at factorize()
  // (SystemOperator::fill) and the sparse K, D and A are formed only when asked for (K(), D(),
  // A(), an LDLT fallback): Newton needs only the product and dampingQuadratic.
  ImplicitSystem(const LinearSolverOptions& linearSolver, bool clampCompression,
                 bool directOperator = false);
  ~ImplicitSystem();

  // Binds to `model`; true when it is another model than the last (the pattern is rebuilt and
  // the solver analyses afresh: integrators must forget their history then).
  bool bind(const Model& model);
  bool bound() const { return jacobian_ != nullptr; }
  // Whether A's blocks come straight from the springs (directOperator, where it applies).
  bool fillsDirectly() const { return direct_; }

  // K and D at positions x and velocities v (3n each; v: friction's D, src/effects/obstacle.h,
  // left out when null): the last assembly until the next.
  void assemble(const double* x, const double* v);
  // A = M - a D - b K of the last assembly, written into A().
  void formMatrix(double a, double b);
  // A as formed, factored (CHOLMOD) or prepared (CG: the preconditioner set up and, matrix-free,
  // A's blocks gathered for the product; CG then solves with this A until the next factorize).
  StepResult factorize();
  // formMatrix(a, b), then factorize().
  StepResult factorize(double a, double b);
  // x: on entry CG's initial guess, on return the solution of A x = rhs. ldltFallback false: an
  // indefinite A fails the solve (solver().indefinite()) instead of falling back to LDLT, for a
  // caller that clamps then (Newton on demand: an LDLT of A at 16^3 costs seconds).
  StepResult solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, bool ldltFallback = true);

  // The projective matrix P(a, b) = M + L(a c + b k) + C on each coordinate of the bound model
  // (solvers/system/spring_laplacian.h), factored when a, b or C changed: CG's projective
  // preconditioner and Newton's seed iterations. C, diagonal, bounds the contact springs' part of
  // A: per point in contact, b kc + a dc for each wall, the plane, the sphere and each obstacle
  // it is inside of (kc n n^T <= kc I), given as `contact` (n values, null: none). factorize()
  // sets P up itself for CG, with the contacts of the last assembly's positions, keeping the
  // factor it has while they differ from its C by light contacts only (lightContactsAt's test:
  // P stays SPD and close to A, and CG converged as fast on jello.w, without a factorization
  // at each contact change).
  StepResult factorProjective(double a, double b, const Eigen::VectorXd* contact = nullptr);
  // P(a, b) for Newton's seeds: the factor kept when it is for a and b, whatever C it holds
  // (the preconditioner's contacts: lightContactsAt corrects for the difference); else
  // factorProjective(a, b) without contacts.
  StepResult factorProjectiveForSeeds(double a, double b);
  // v <- P^-1 v (3n, component-major) with the last factorProjective.
  StepResult solveProjective(Eigen::VectorXd& v) const;
  // Newton's seeds through contact: the contact diagonal at positions x (3n), against the C
  // that P holds. Each difference lighter than half its point's diagonal of P without contacts
  // is left to a correction of the seed's update on a coarse lattice (correctProjective, as
  // projective's: solvers/system/lattice_coarse_space.h); false when one is heavier, or the
  // model is not a lattice of kCoarseNodes^3 points or more (the seeds then stop at contact).
  bool lightContactsAt(const double* x);
  // After solveProjective(v): v corrected for the contacts of the last lightContactsAt
  // (nothing when P holds them all).
  StepResult correctProjective(Eigen::VectorXd& v);

  // The last assembly's K and D (formed on demand under directOperator).
  const SparseMatrix& K();
  const SparseMatrix& D();
  // v^T D v with the last assembly's D (3n), without forming D under directOperator.
  double dampingQuadratic(const Eigen::VectorXd& v);
  double frictionQuadratic(const double* v) const { return jacobian_->frictionQuadratic(v); }
  // Whether the next assembly projects compressed springs' Hessians (the clamp).
  void setClampCompression(bool clamp) { clampCompression_ = clamp; }
  bool clampsCompression() const { return clampCompression_; }

  // The last formMatrix's A (formed on demand under directOperator).
  const SparseMatrix& A();
  const SpdSolver& solver() const { return solver_; }
  long clampCount() const { return clamps_; }

  // compression_clamps, factorizations, ldlt_fallbacks, assemble/factor/solve times and (CG)
  // cg_iterations, appended to out.
  void appendStatistics(std::vector<Statistic>& out) const;

 private:
  // True when P, factored for the current a and b, differs from P with `contact` by light
  // contacts only (see factorize()).
  bool keepsProjective(const Eigen::VectorXd& contact);
  // difference = contact - the C P holds; true when every entry is light (coarse_'s test).
  bool lightAgainstFactor(const Eigen::VectorXd& contact, Eigen::VectorXd& difference) const;
  // directOperator: the sparse K and D of the last assembly at x_ and v_, with the clamp it
  // had (formMatrices), and A for a_ and b_, formed only when asked for.
  void formMatrices();
  bool clampCompression_;
  bool direct_;
  bool assembledClamp_ = true;
  bool matricesStale_ = false, matrixStale_ = false;
  Eigen::VectorXd v_;   // the last assembly's velocities (directOperator; empty: none)
  Eigen::VectorXd dv_;  // dampingQuadratic's D v
  long clamps_ = 0;
  long modelId_ = -1;
  const Model* model_ = nullptr;  // the one of the last bind: alive while a step runs
  bool matrixFree_;
  std::unique_ptr<JacobianAssembler> jacobian_;
  std::unique_ptr<SystemOperator> operator_;  // cg, matrix-free
  SparseMatrix A_;
  double a_ = 0.0, b_ = 0.0;  // of the last formMatrix
  SpdSolver solver_;
  std::unique_ptr<SpringLaplacian> laplacian_;  // projective: built on first use per model
  std::unique_ptr<PrefactoredCholesky> projective_;
  SparseMatrix projectiveMatrix_;
  double projectiveA_ = -1.0, projectiveB_ = -1.0;  // what projective_ holds
  Eigen::VectorXd projectiveContact_;               // C of projective_ (empty: none)
  Eigen::VectorXd x_, contact_;                     // the last assembly's positions; C there
  // The seeds' coarse correction: its space (null: not a lattice; its base is P without C), the
  // wanted C and its difference from P's (lightContactsAt), and whether there is one to correct.
  std::unique_ptr<LatticeCoarseSpace> coarse_;
  Eigen::VectorXd wantedContact_, contactDifference_;
  Eigen::VectorXd preconditionerDifference_;  // keepsProjective's
  SparseMatrix freeMatrix_;
  bool correctContacts_ = false;
  long projectiveFactorizations_ = 0;
  double projectiveSeconds_ = 0.0;
  double assembleSeconds_ = 0.0;
};

}  // namespace jello
