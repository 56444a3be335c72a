// Solves A x = b for the symmetric systems of the implicit integrators, A = M - a D - b K
// (3n x 3n, fixed pattern). Three methods:
//   cholmod  CHOLMOD supernodal LLT (through Eigen's CholmodSupport): symbolic analysis once,
//            numeric factorization per matrix. If A is not positive definite (possible only
//            with the compression clamp off), it falls back to CHOLMOD's simplicial LDLT, and
//            the solution is accepted only if its residual |Ax - b| <= 1e-8 |b|. Fallbacks are
//            counted.
//   ldlt     CHOLMOD simplicial LDLT, residual-checked the same way.
//   cg       conjugate gradients with a Jacobi preconditioner, warm-started from x.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "solvers/jacobian.h"
#include "solvers/step_result.h"

namespace jello {

enum class LinearSolverKind { Cholmod, Ldlt, Cg };

std::optional<LinearSolverKind> parseLinearSolver(std::string_view name);
std::string_view linearSolverName(LinearSolverKind kind);

struct LinearSolverStats {
  long analyses = 0;
  long factorizations = 0;
  long solves = 0;
  long fallbacks = 0;     // LLT failed, LDLT used
  long cgIterations = 0;  // summed over solves
  double factorSeconds = 0.0;
  double solveSeconds = 0.0;
};

class SpdSolver {
 public:
  explicit SpdSolver(LinearSolverKind kind, double cgTolerance = 1e-6);
  ~SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;

  // Prepares to solve with A; every A passed must have the same pattern until forgetPattern().
  StepResult factorize(const SparseMatrix& A);
  // The next factorize analyzes its matrix's pattern afresh (a new model).
  void forgetPattern();
  // x: on entry the initial guess (cg), on return the solution.
  StepResult solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

  LinearSolverKind kind() const { return kind_; }
  const LinearSolverStats& stats() const { return stats_; }

 private:
  struct Impl;
  LinearSolverKind kind_;
  std::unique_ptr<Impl> impl_;
  LinearSolverStats stats_;
};

}  // namespace jello
