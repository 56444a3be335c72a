#include "solvers/implicit_system.h"

#include <chrono>

#include "src/assertions.h"

namespace jello {

ImplicitSystem::ImplicitSystem(const LinearSolverOptions& linearSolver, bool clampCompression)
    : clampCompression_(clampCompression),
      matrixFree_(linearSolver.kind == LinearSolverKind::Cg && linearSolver.matrixFree),
      solver_(linearSolver) {}

bool ImplicitSystem::bind(const Model& model) {
  if (model.id() == modelId_) return false;
  modelId_ = model.id();
  jacobian_ = std::make_unique<JacobianAssembler>(model);
  if (matrixFree_) operator_ = std::make_unique<SystemOperator>(model.springs(), model.numPoints());
  A_ = jacobian_->pattern();
  solver_.forgetPattern();
  return true;
}

void ImplicitSystem::assemble(const double* x) {
  JELLO_ASSERT(bound(), "the implicit system is bound to a model before it assembles");
  const auto start = std::chrono::steady_clock::now();
  jacobian_->assemble(x, {clampCompression_, false});
  assembleSeconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void ImplicitSystem::formMatrix(double a, double b) {
  jacobian_->combine(a, b, A_);
}

StepResult ImplicitSystem::factorize() {
  if (operator_) operator_->gather(A_, jacobian_->diagonalSlots(), jacobian_->springSlots());
  return solver_.factorize(A_, operator_.get());
}

StepResult ImplicitSystem::factorize(double a, double b) {
  formMatrix(a, b);
  return factorize();
}

StepResult ImplicitSystem::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) {
  return solver_.solve(rhs, x);
}

void ImplicitSystem::appendStatistics(std::vector<Statistic>& out) const {
  const LinearSolverStats& ls = solver_.stats();
  out.push_back({"compression_clamps", static_cast<double>(clampCount())});
  out.push_back({"factorizations", static_cast<double>(ls.factorizations)});
  out.push_back({"ldlt_fallbacks", static_cast<double>(ls.fallbacks)});
  out.push_back({"assemble_time_s", assembleSeconds_});
  out.push_back({"factor_time_s", ls.factorSeconds});
  out.push_back({"solve_time_s", ls.solveSeconds});
  if (solver_.kind() == LinearSolverKind::Cg) {
    out.push_back({"cg_iterations", static_cast<double>(ls.cgIterations)});
    if (solver_.preconditioner() == PreconditionerKind::IncompleteCholesky ||
        solver_.preconditioner() == PreconditionerKind::Factor) {
      out.push_back(
          {"preconditioner_factorizations", static_cast<double>(ls.preconditionerFactorizations)});
    }
  }
}

}  // namespace jello
