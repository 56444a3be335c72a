#include "solvers/linear_solver.h"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <chrono>

namespace jello {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr double kResidualTolerance = 1e-8;

}  // namespace

struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
  Eigen::CholmodSimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double>>
      cg;
  bool lltAnalyzed = false;
  bool ldltAnalyzed = false;
  bool useLdlt = false;             // this factorization went to LDLT
  const SparseMatrix* A = nullptr;  // for the residual check

  Impl() {
    // CHOLMOD prints warnings to stdout by default: we report failures ourselves.
    llt.cholmod().print = 0;
    ldlt.cholmod().print = 0;
  }

  StepResult factorLdlt(const SparseMatrix& m, LinearSolverStats& stats) {
    if (!ldltAnalyzed) {
      ldlt.analyzePattern(m);
      ++stats.analyses;
      if (ldlt.info() != Eigen::Success) return StepResult::failure("LDLT analysis failed");
      ldltAnalyzed = true;
    }
    ldlt.factorize(m);
    if (ldlt.info() != Eigen::Success) {
      return StepResult::failure("the LDLT factorization failed (singular system)");
    }
    return StepResult::success();
  }
};

std::optional<LinearSolverKind> parseLinearSolver(std::string_view name) {
  if (name == "cholmod") return LinearSolverKind::Cholmod;
  if (name == "ldlt") return LinearSolverKind::Ldlt;
  if (name == "cg") return LinearSolverKind::Cg;
  return std::nullopt;
}

std::string_view linearSolverName(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::Cholmod:
      return "cholmod";
    case LinearSolverKind::Ldlt:
      return "ldlt";
    case LinearSolverKind::Cg:
      return "cg";
  }
  return "?";
}

SpdSolver::SpdSolver(LinearSolverKind kind, double cgTolerance)
    : kind_(kind), impl_(std::make_unique<Impl>()) {
  impl_->cg.setTolerance(cgTolerance);
}

SpdSolver::~SpdSolver() = default;

void SpdSolver::forgetPattern() {
  impl_->lltAnalyzed = false;
  impl_->ldltAnalyzed = false;
}

StepResult SpdSolver::factorize(const SparseMatrix& A) {
  const auto start = Clock::now();
  Impl& s = *impl_;
  s.A = &A;
  s.useLdlt = false;
  StepResult result = StepResult::success();
  switch (kind_) {
    case LinearSolverKind::Cholmod:
      if (!s.lltAnalyzed) {
        s.llt.analyzePattern(A);
        ++stats_.analyses;
        if (s.llt.info() != Eigen::Success) {
          result = StepResult::failure("CHOLMOD analysis failed");
          break;
        }
        s.lltAnalyzed = true;
      }
      s.llt.factorize(A);
      if (s.llt.info() == Eigen::Success) break;
      // Not positive definite: fall back to LDLT, checked by the solution's residual.
      ++stats_.fallbacks;
      s.useLdlt = true;
      result = s.factorLdlt(A, stats_);
      break;
    case LinearSolverKind::Ldlt:
      s.useLdlt = true;
      result = s.factorLdlt(A, stats_);
      break;
    case LinearSolverKind::Cg:
      s.cg.compute(A);
      if (s.cg.info() != Eigen::Success) result = StepResult::failure("CG set-up failed");
      break;
  }
  ++stats_.factorizations;
  stats_.factorSeconds += secondsSince(start);
  return result;
}

StepResult SpdSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  const auto start = Clock::now();
  Impl& s = *impl_;
  StepResult result = StepResult::success();
  if (kind_ == LinearSolverKind::Cg) {
    if (x.size() != b.size()) x.setZero(b.size());
    x = s.cg.solveWithGuess(b, x);
    stats_.cgIterations += s.cg.iterations();
    if (s.cg.info() != Eigen::Success) {
      result = StepResult::failure("CG did not converge in " + std::to_string(s.cg.iterations()) +
                                   " iterations (error " + std::to_string(s.cg.error()) + ")");
    }
  } else if (s.useLdlt) {
    x = s.ldlt.solve(b);
    if (s.ldlt.info() != Eigen::Success) {
      result = StepResult::failure("the LDLT solve failed");
    } else {
      // LDLT succeeds silently on singular or badly indefinite systems: check the answer.
      const double residual = (*s.A * x - b).norm(), scale = b.norm();
      if (!(residual <= kResidualTolerance * scale)) {
        result = StepResult::failure("the LDLT solution is inaccurate (relative residual " +
                                     std::to_string(residual / scale) + ")");
      }
    }
  } else {
    x = s.llt.solve(b);
    if (s.llt.info() != Eigen::Success) result = StepResult::failure("the CHOLMOD solve failed");
  }
  if (result.ok && !x.allFinite()) result = StepResult::failure("the solution is not finite");
  ++stats_.solves;
  stats_.solveSeconds += secondsSince(start);
  return result;
}

}  // namespace jello
