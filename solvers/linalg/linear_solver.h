// Solves A x = b for the symmetric systems of the implicit integrators, A = M - a D - b K
// (3n x 3n, fixed pattern). Three methods:
//   cholmod  CHOLMOD supernodal LLT (through Eigen's CholmodSupport): symbolic analysis once,
//            numeric factorization per matrix. If A is not positive definite (possible only
//            with the compression clamp off), it falls back to CHOLMOD's simplicial LDLT, and
//            the solution is accepted only if its residual |Ax - b| <= 1e-8 |b|. Fallbacks are
//            counted.
//   ldlt     CHOLMOD simplicial LDLT, residual-checked the same way.
//   cg       preconditioned conjugate gradients, warm-started from x, on the sparse matrix or,
//            given a LinearOperator (solvers/system/system_operator.h: matrix-free through the
//            spring kernels). Preconditioners:
//              jacobi        the diagonal of A
//              block-jacobi  each point's 3x3 diagonal block of A, inverted
//              ichol         incomplete Cholesky of A (Eigen, AMD ordering, shifted if needed)
//              factor        a CHOLMOD factorization of an earlier A, kept while CG converges
//                            in few iterations (at most kStaleFactorIterations) and refreshed at
//                            the next set-up after a solve that needed more
//              projective    the springs' Laplacian M + L(a c + b k) on each coordinate
//                            (solvers/system/spring_laplacian.h), factored once per a and b: it
//                            bounds A's spring part from above, so it is kept however the cube
//                            turns
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "solvers/linalg/linear_operator.h"
#include "solvers/linalg/sparse_matrix.h"
#include "solvers/step_result.h"

namespace jello {

enum class LinearSolverKind { Cholmod, Ldlt, Cg };
enum class PreconditionerKind { Jacobi, BlockJacobi, IncompleteCholesky, Factor, Projective };

std::optional<LinearSolverKind> parseLinearSolver(std::string_view name);
std::string_view linearSolverName(LinearSolverKind kind);
// "jacobi", "block-jacobi", "ichol", "factor", "projective".
std::optional<PreconditionerKind> parsePreconditioner(std::string_view name);
std::string_view preconditionerName(PreconditionerKind kind);

// A stale factor is refreshed after a solve that took more CG iterations than this.
inline constexpr int kStaleFactorIterations = 10;

struct LinearSolverOptions {
  LinearSolverKind kind = LinearSolverKind::Cholmod;
  double cgTolerance = 1e-6;  // relative residual |A x - b| <= tol |b|
  PreconditionerKind preconditioner = PreconditionerKind::Jacobi;
  bool matrixFree = true;  // cg: the product through the spring kernels where it is given
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
  // The next factorize analyzes its matrix's pattern afresh (a new model).
  void forgetPattern();
  // x: on entry the initial guess (cg), on return the solution.
  StepResult solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

  LinearSolverKind kind() const { return kind_; }
  PreconditionerKind preconditioner() const { return preconditioner_; }
  const LinearSolverStats& stats() const { return stats_; }

 private:
  struct Impl;
  StepResult setUpPreconditioner(const SparseMatrix& A);
  StepResult conjugateGradients(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  LinearSolverKind kind_;
  PreconditionerKind preconditioner_ = PreconditionerKind::Jacobi;
  double cgTolerance_;
  std::unique_ptr<Impl> impl_;
  LinearSolverStats stats_;
};

}  // namespace jello
