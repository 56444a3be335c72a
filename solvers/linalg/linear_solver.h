// Solves A x = b for the symmetric systems of the implicit integrators, A = M - a D - b K
// (3n x 3n, fixed pattern), by one of the linear solvers of the table below:
//   cholmod  symbolic analysis once, numeric factorization per matrix. If A is not positive
//            definite (possible only with the compression clamp off), it falls back to
//            CHOLMOD's simplicial LDLT, and the solution is accepted only if its residual
//            |Ax - b| <= 1e-8 |b|. Fallbacks are counted.
//   ldlt     residual-checked the same way.
//   cg       warm-started from x, on the sparse matrix or, given a LinearOperator, through its
//            product (solvers/system/system_operator.h: matrix-free through the spring
//            kernels), with one of the preconditioners of the second table. `factor` is kept
//            while CG converges in at most kStaleFactorIterations and refreshed at the next
//            set-up after a solve that needed more; `projective` solves with a factored matrix
//            the caller gives (the implicit system's spring Laplacian, which bounds A's spring
//            part from above, so it is kept however the cube turns).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "solvers/linalg/linear_operator.h"
#include "solvers/linalg/sparse_matrix.h"
#include "solvers/step_result.h"

namespace jello {

// A solve's residual |A x - b| for a message: relative to |b| = `scale`, or why it cannot be
// ("relative residual -nan" said nothing: the solution was not finite).
std::string describeResidual(double residual, double scale);

// The one table of linear solvers and the one of CG's preconditioners: enumerator, name, what
// it is (help texts, the panel, the Python module and the studies read them from here).
#define JELLO_LINEAR_SOLVERS(X)                                                \
  X(Cholmod, "cholmod", "supernodal LLT (CHOLMOD), factored per matrix")       \
  X(Ldlt, "ldlt", "simplicial LDLT (CHOLMOD), its solutions residual-checked") \
  X(Cg, "cg", "conjugate gradients: preconditioned, warm-started, matrix-free")
#define JELLO_PRECONDITIONERS(X)                                                           \
  X(Jacobi, "jacobi", "the diagonal")                                                      \
  X(BlockJacobi, "block-jacobi", "each point's 3x3 block")                                 \
  X(IncompleteCholesky, "ichol", "incomplete Cholesky")                                    \
  X(Factor, "factor",                                                                      \
    "a CHOLMOD factor of an earlier matrix, refreshed when CG needs more than 10 "         \
    "iterations")                                                                          \
  X(Projective, "projective",                                                              \
    "the springs' Laplacian M + L(a c + b k) with the contacts on its diagonal, factored " \
    "once per step size and again when a heavy contact comes or goes")

enum class LinearSolverKind {
#define JELLO_LINEAR_SOLVER_ENUMERATOR(kind, name, summary) kind,
  JELLO_LINEAR_SOLVERS(JELLO_LINEAR_SOLVER_ENUMERATOR)
#undef JELLO_LINEAR_SOLVER_ENUMERATOR
};
enum class PreconditionerKind {
#define JELLO_PRECONDITIONER_ENUMERATOR(kind, name, summary) kind,
  JELLO_PRECONDITIONERS(JELLO_PRECONDITIONER_ENUMERATOR)
#undef JELLO_PRECONDITIONER_ENUMERATOR
};

// The default of every implicit integrator and of CVODE: CG (Jacobi, matrix-free) takes the
// same converged steps in well under CHOLMOD's time on jello.w and the spinning cube; CHOLMOD
// stays faster where one kept factorization serves every step (a stiff cube at rest).
inline constexpr LinearSolverKind kDefaultLinearSolver = LinearSolverKind::Cg;
inline constexpr PreconditionerKind kDefaultPreconditioner = PreconditionerKind::Jacobi;

// Names in any case; every name in the table's order; each one's summary.
std::optional<LinearSolverKind> parseLinearSolver(std::string_view name);
std::string_view linearSolverName(LinearSolverKind kind);
std::string_view linearSolverSummary(LinearSolverKind kind);
std::span<const LinearSolverKind> allLinearSolvers();
std::optional<PreconditionerKind> parsePreconditioner(std::string_view name);
std::string_view preconditionerName(PreconditionerKind kind);
std::string_view preconditionerSummary(PreconditionerKind kind);
// Whether the preconditioner is built from the sparse matrix A itself (ichol, factor), not from
// an operator's diagonal blocks or the projective factor: SpdSolver::prepare takes the others.
bool preconditionerNeedsMatrix(PreconditionerKind kind);
std::span<const PreconditionerKind> allPreconditioners();

// A stale factor is refreshed after a solve that took more CG iterations than this.
inline constexpr int kStaleFactorIterations = 10;

struct LinearSolverOptions {
  LinearSolverKind kind = kDefaultLinearSolver;
  double cgTolerance = 1e-6;  // relative residual |A x - b| <= tol |b|
  PreconditionerKind preconditioner = kDefaultPreconditioner;
  bool matrixFree = true;  // cg: the product through the operator where one is given
};

class PrefactoredCholesky;

struct LinearSolverStats {
  long analyses = 0;
  long factorizations = 0;
  long solves = 0;
  long fallbacks = 0;                     // LLT failed, LDLT used
  long cgIterations = 0;                  // summed over solves
  long preconditionerFactorizations = 0;  // ichol and factor: set-ups that factored afresh
  double factorSeconds = 0.0;
  double solveSeconds = 0.0;
};

class SpdSolver {
 public:
  explicit SpdSolver(LinearSolverKind kind, double cgTolerance = 1e-6);
  explicit SpdSolver(const LinearSolverOptions& options);
  ~SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;

  // Prepares to solve with A; every A passed must have the same pattern until forgetPattern().
  // cg: `op`, when given, holds the same A (gathered) and takes the products; `projective`, the
  // factored Laplacian the projective preconditioner solves with (required for it).
  StepResult factorize(const SparseMatrix& A, const LinearOperator* op = nullptr,
                       const PrefactoredCholesky* projective = nullptr);
  // cg, matrix-free, without a sparse A: prepares to solve with the matrix `op` holds (n3 rows),
  // for the preconditioners that need no A (jacobi and block-jacobi from op's diagonal blocks,
  // projective). A solve that meets a direction of non-positive curvature then fails with
  // indefinite() set instead of falling back to LDLT: the caller forms A for fallBackToLdlt.
  StepResult prepare(const LinearOperator& op, Eigen::Index n3,
                     const PrefactoredCholesky* projective = nullptr);
  bool indefinite() const;
  // LDLT of A (the matrix of the last prepare, formed), counted as a fallback, then x = A^-1 b;
  // the solves until the next factorize or prepare stay with it, as factorize's fallback does.
  StepResult fallBackToLdlt(const SparseMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x);
  // The next factorize analyzes its matrix's pattern afresh (a new model).
  void forgetPattern();
  // x: on entry the initial guess (cg), on return the solution. ldltFallback false: CG meeting
  // a direction of non-positive curvature fails the solve (indefinite()) without LDLT.
  StepResult solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, bool ldltFallback = true);

  LinearSolverKind kind() const { return kind_; }
  PreconditionerKind preconditioner() const { return preconditioner_; }
  const LinearSolverStats& stats() const { return stats_; }

 private:
  struct Impl;
  // A: null where the operator holds the matrix (prepare).
  StepResult setUpPreconditioner(const SparseMatrix* A, Eigen::Index n3);
  StepResult conjugateGradients(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  LinearSolverKind kind_;
  PreconditionerKind preconditioner_ = PreconditionerKind::Jacobi;
  double cgTolerance_;
  std::unique_ptr<Impl> impl_;
  LinearSolverStats stats_;
};

}  // namespace jello
