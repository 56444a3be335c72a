#include "solvers/linalg/linear_solver.h"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <array>
#include <chrono>
#include <cmath>
#include <sstream>

#include "solvers/linalg/blas_headroom.h"
#include "solvers/linalg/prefactored_cholesky.h"
#include "src/base/assertions.h"
#include "src/base/closed_set.h"

namespace jello {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr double kResidualTolerance = 1e-8;

// The diagonal of the operator's matrix (3n), from its points' diagonal blocks.
Eigen::VectorXd operatorDiagonal(const LinearOperator& op, Eigen::Index n) {
  const std::array<const double*, 6> g = op.diagonalBlocks();
  Eigen::VectorXd d(3 * n);
  d << Eigen::Map<const Eigen::VectorXd>(g[0], n), Eigen::Map<const Eigen::VectorXd>(g[3], n),
      Eigen::Map<const Eigen::VectorXd>(g[5], n);
  return d;
}

}  // namespace

std::string describeResidual(double residual, double scale) {
  std::ostringstream os;
  if (!std::isfinite(residual)) {
    os << "the residual is not finite: the solution holds NaN or infinity";
  } else if (!(scale > 0.0) || !std::isfinite(scale)) {
    os << "residual " << residual << " against a right-hand side of norm " << scale;
  } else {
    os << "relative residual " << residual / scale;
  }
  return os.str();
}

struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;  // cholmod; cg's stale factor
  Eigen::CholmodSimplicialLDLT<SparseMatrix, Eigen::Lower> ldlt;
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>> ichol;
  bool lltAnalyzed = false;
  // cg: the operator (or A itself), the preconditioner's data, the work vectors.
  const LinearOperator* op = nullptr;
  const PrefactoredCholesky* projective = nullptr;  // projective
  Eigen::VectorXd invDiagonal;                      // jacobi
  std::array<Eigen::VectorXd, 6> blockInverse;      // block-jacobi: per point, upper triangle
  bool staleFactor = false;                         // factor: llt holds an earlier A's factor
  bool icholAnalyzed = false;
  long lastIterations = 0;
  Eigen::VectorXd r, z, p, q;
  bool ldltAnalyzed = false;
  bool useLdlt = false;             // this factorization went to LDLT
  bool indefinite = false;          // cg met a direction of non-positive curvature
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

  // LDLT succeeds silently on singular or badly indefinite systems: the answer is checked.
  StepResult solveLdlt(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    x = ldlt.solve(b);
    if (ldlt.info() != Eigen::Success) return StepResult::failure("the LDLT solve failed");
    const double residual = (*A * x - b).norm(), scale = b.norm();
    if (!(residual <= kResidualTolerance * scale)) {
      return StepResult::failure("the LDLT solution is inaccurate (" +
                                 describeResidual(residual, scale) + ")");
    }
    return StepResult::success();
  }
};

namespace {

// The inverse of each point's symmetric 3x3 block (xx, xy, xz, yy, yz, zz arrays); false when
// a block is not positive definite.
bool invertBlocks(const std::array<const double*, 6>& g, Eigen::Index n,
                  std::array<Eigen::VectorXd, 6>& inv) {
  for (auto& v : inv) v.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double a = g[0][i], b = g[1][i], c = g[2][i], d = g[3][i], e = g[4][i], f = g[5][i];
    // Cofactors of [[a b c] [b d e] [c e f]].
    const double A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;
    const double det = a * A + b * B + c * C;
    if (!(a > 0.0 && a * d - b * b > 0.0 && det > 0.0) || !std::isfinite(det)) return false;
    const double s = 1.0 / det;
    inv[0][i] = A * s;
    inv[1][i] = B * s;
    inv[2][i] = C * s;
    inv[3][i] = (a * f - c * c) * s;
    inv[4][i] = (b * c - a * e) * s;
    inv[5][i] = (a * d - b * b) * s;
  }
  return true;
}

}  // namespace

namespace {

constexpr closed_set::Row<LinearSolverKind> kLinearSolvers[] = {
#define JELLO_LINEAR_SOLVER_ROW(kind, name, summary) {LinearSolverKind::kind, name, summary},
    JELLO_LINEAR_SOLVERS(JELLO_LINEAR_SOLVER_ROW)
#undef JELLO_LINEAR_SOLVER_ROW
};
constexpr auto kLinearSolverKinds = closed_set::kinds(kLinearSolvers);
constexpr closed_set::Row<PreconditionerKind> kPreconditioners[] = {
#define JELLO_PRECONDITIONER_ROW(kind, name, summary) {PreconditionerKind::kind, name, summary},
    JELLO_PRECONDITIONERS(JELLO_PRECONDITIONER_ROW)
#undef JELLO_PRECONDITIONER_ROW
};
constexpr auto kPreconditionerKinds = closed_set::kinds(kPreconditioners);

}  // namespace

std::optional<LinearSolverKind> parseLinearSolver(std::string_view name) {
  return closed_set::parse(kLinearSolvers, name);
}
std::string_view linearSolverName(LinearSolverKind kind) {
  return closed_set::row(kLinearSolvers, kind).name;
}
std::string_view linearSolverSummary(LinearSolverKind kind) {
  return closed_set::row(kLinearSolvers, kind).summary;
}
std::span<const LinearSolverKind> allLinearSolvers() {
  return kLinearSolverKinds;
}
std::optional<PreconditionerKind> parsePreconditioner(std::string_view name) {
  return closed_set::parse(kPreconditioners, name);
}
std::string_view preconditionerName(PreconditionerKind kind) {
  return closed_set::row(kPreconditioners, kind).name;
}
std::string_view preconditionerSummary(PreconditionerKind kind) {
  return closed_set::row(kPreconditioners, kind).summary;
}
std::span<const PreconditionerKind> allPreconditioners() {
  return kPreconditionerKinds;
}

SpdSolver::SpdSolver(LinearSolverKind kind, double cgTolerance)
    : SpdSolver(LinearSolverOptions{kind, cgTolerance}) {}

SpdSolver::SpdSolver(const LinearSolverOptions& options)
    : kind_(options.kind),
      preconditioner_(options.preconditioner),
      cgTolerance_(options.cgTolerance),
      impl_(std::make_unique<Impl>()) {}

SpdSolver::~SpdSolver() = default;

void SpdSolver::forgetPattern() {
  impl_->lltAnalyzed = false;
  impl_->ldltAnalyzed = false;
  impl_->icholAnalyzed = false;
  impl_->staleFactor = false;
}

bool preconditionerNeedsMatrix(PreconditionerKind kind) {
  return kind == PreconditionerKind::IncompleteCholesky || kind == PreconditionerKind::Factor;
}

StepResult SpdSolver::setUpPreconditioner(const SparseMatrix* A, Eigen::Index n3) {
  Impl& s = *impl_;
  const Eigen::Index n = n3 / 3;
  JELLO_ASSERT(A || (s.op && !preconditionerNeedsMatrix(preconditioner_)),
               "a preconditioner without A takes the operator's");
  switch (preconditioner_) {
    case PreconditionerKind::Jacobi: {
      const Eigen::VectorXd d = s.op ? operatorDiagonal(*s.op, n) : Eigen::VectorXd(A->diagonal());
      if (!(d.minCoeff() > 0.0)) {
        return StepResult::failure("Jacobi preconditioner: a diagonal entry is not positive");
      }
      s.invDiagonal = d.cwiseInverse();
      return StepResult::success();
    }
    case PreconditionerKind::BlockJacobi: {
      std::array<Eigen::VectorXd, 6> blocks;  // from A when there is no operator
      std::array<const double*, 6> g{};
      if (s.op) {
        g = s.op->diagonalBlocks();
      } else {
        constexpr int rows[6] = {0, 0, 0, 1, 1, 2}, cols[6] = {0, 1, 2, 1, 2, 2};
        for (int e = 0; e < 6; ++e) {
          blocks[e].resize(n);
          for (Eigen::Index i = 0; i < n; ++i)
            blocks[e][i] = A->coeff(rows[e] * n + i, cols[e] * n + i);
          g[e] = blocks[e].data();
        }
      }
      if (!invertBlocks(g, n, s.blockInverse)) {
        return StepResult::failure("block-Jacobi preconditioner: a block is not positive definite");
      }
      return StepResult::success();
    }
    case PreconditionerKind::IncompleteCholesky:
      if (!s.icholAnalyzed) {
        s.ichol.analyzePattern(*A);
        s.icholAnalyzed = true;
      }
      s.ichol.factorize(*A);
      ++stats_.preconditionerFactorizations;
      if (s.ichol.info() != Eigen::Success) {
        return StepResult::failure("incomplete Cholesky failed");
      }
      return StepResult::success();
    case PreconditionerKind::Factor:
      if (s.staleFactor && s.lastIterations <= kStaleFactorIterations) {
        return StepResult::success();  // the earlier factor still serves
      }
      if (!s.lltAnalyzed) {
        s.llt.analyzePattern(*A);
        ++stats_.analyses;
        if (s.llt.info() != Eigen::Success) return StepResult::failure("CHOLMOD analysis failed");
        s.lltAnalyzed = true;
      }
      if (const std::string why = blasHeadroomProblem(); !why.empty()) {
        return StepResult::resourceFailure(why);
      }
      s.llt.factorize(*A);
      ++stats_.preconditionerFactorizations;
      s.lastIterations = 0;
      s.staleFactor = s.llt.info() == Eigen::Success;
      if (!s.staleFactor) {
        return StepResult::failure(
            "the preconditioner's factorization failed (not positive definite)");
      }
      return StepResult::success();
    case PreconditionerKind::Projective:
      if (!s.projective || !s.projective->factored() || s.projective->size() * 3 != n3) {
        return StepResult::failure("the projective preconditioner has no factored Laplacian");
      }
      return StepResult::success();
  }
  return StepResult::success();
}

// Long: one preconditioned CG iteration loop, each preconditioner's application inline in it.
StepResult SpdSolver::conjugateGradients(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& s = *impl_;
  const Eigen::Index n3 = b.size(), n = n3 / 3;
  if (x.size() != n3) x.setZero(n3);
  const auto product = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    out.resize(n3);
    if (s.op) {
      s.op->apply(v.data(), out.data());
    } else {
      out.noalias() = *s.A * v;
    }
  };
  StepResult preconditioned = StepResult::success();
  const auto precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    switch (preconditioner_) {
      case PreconditionerKind::Jacobi:
        z = s.invDiagonal.cwiseProduct(r);
        break;
      case PreconditionerKind::BlockJacobi: {
        z.resize(n3);
        const auto& m = s.blockInverse;
        for (Eigen::Index i = 0; i < n; ++i) {
          const double rx = r[i], ry = r[n + i], rz = r[2 * n + i];
          z[i] = m[0][i] * rx + m[1][i] * ry + m[2][i] * rz;
          z[n + i] = m[1][i] * rx + m[3][i] * ry + m[4][i] * rz;
          z[2 * n + i] = m[2][i] * rx + m[4][i] * ry + m[5][i] * rz;
        }
        break;
      }
      case PreconditionerKind::IncompleteCholesky:
        z = s.ichol.solve(r);
        break;
      case PreconditionerKind::Factor:
        z = s.llt.solve(r);
        break;
      case PreconditionerKind::Projective:
        z = r;  // component-major: the x, y and z columns of one n x 3 system
        if (preconditioned.ok) preconditioned = s.projective->solve(z.data(), 3);
        break;
    }
  };
  const double bNorm = b.norm();
  if (bNorm == 0.0) {
    x.setZero();
    s.lastIterations = 0;
    return StepResult::success();
  }
  const double tolerance = cgTolerance_ * bNorm;
  const long maxIterations = std::max<long>(10, 2 * n3);
  product(x, s.q);
  s.r = b - s.q;
  double residual = s.r.norm();
  long it = 0;
  if (residual > tolerance) {
    precondition(s.r, s.z);
    if (!preconditioned.ok) return preconditioned;
    s.p = s.z;
    double rz = s.r.dot(s.z);
    while (true) {
      product(s.p, s.q);
      const double pq = s.p.dot(s.q);
      if (!(pq > 0.0)) {
        s.lastIterations = it;
        s.indefinite = true;
        return StepResult::failure(
            "CG: the matrix is not positive definite (p.Ap = " + std::to_string(pq) + ")");
      }
      const double alpha = rz / pq;
      x += alpha * s.p;
      s.r -= alpha * s.q;
      ++it;
      residual = s.r.norm();
      if (residual <= tolerance || it >= maxIterations) break;
      precondition(s.r, s.z);
      if (!preconditioned.ok) return preconditioned;
      const double rzNext = s.r.dot(s.z);
      s.p = s.z + (rzNext / rz) * s.p;
      rz = rzNext;
    }
  }
  stats_.cgIterations += it;
  s.lastIterations = it;
  if (!(residual <= tolerance)) {
    std::ostringstream os;
    os << "CG did not converge in " << it << " iterations (" << describeResidual(residual, bNorm)
       << ")";
    return StepResult::failure(os.str());
  }
  return StepResult::success();
}

StepResult SpdSolver::factorize(const SparseMatrix& A, const LinearOperator* op,
                                const PrefactoredCholesky* projective) {
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
      if (const std::string why = blasHeadroomProblem(); !why.empty()) {
        result = StepResult::resourceFailure(why);
        break;
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
      s.op = op;
      s.projective = projective;
      result = setUpPreconditioner(&A, A.rows());
      break;
  }
  ++stats_.factorizations;
  stats_.factorSeconds += secondsSince(start);
  return result;
}

StepResult SpdSolver::prepare(const LinearOperator& op, Eigen::Index n3,
                              const PrefactoredCholesky* projective) {
  JELLO_ASSERT(kind_ == LinearSolverKind::Cg, "only CG solves with an operator alone");
  const auto start = Clock::now();
  Impl& s = *impl_;
  s.A = nullptr;
  s.useLdlt = false;
  s.op = &op;
  s.projective = projective;
  const StepResult result = setUpPreconditioner(nullptr, n3);
  ++stats_.factorizations;
  stats_.factorSeconds += secondsSince(start);
  return result;
}

bool SpdSolver::indefinite() const {
  return impl_->indefinite;
}

StepResult SpdSolver::fallBackToLdlt(const SparseMatrix& A, const Eigen::VectorXd& b,
                                     Eigen::VectorXd& x) {
  const auto start = Clock::now();
  Impl& s = *impl_;
  ++stats_.fallbacks;
  s.A = &A;
  StepResult result = s.factorLdlt(A, stats_);
  s.useLdlt = result.ok;
  if (result.ok) result = s.solveLdlt(b, x);
  if (result.ok && !x.allFinite()) result = StepResult::failure("the solution is not finite");
  stats_.solveSeconds += secondsSince(start);
  return result;
}

StepResult SpdSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x, bool ldltFallback) {
  const auto start = Clock::now();
  Impl& s = *impl_;
  StepResult result = StepResult::success();
  if (kind_ == LinearSolverKind::Cg && !s.useLdlt) {
    s.indefinite = false;
    result = conjugateGradients(b, x);
    // Not positive definite (possible only with the clamp off): LDLT until the next factorize,
    // as cholmod falls back.
    if (!result.ok && s.indefinite && s.A && ldltFallback) {
      ++stats_.fallbacks;
      result = s.factorLdlt(*s.A, stats_);
      s.useLdlt = result.ok;
      if (result.ok) result = s.solveLdlt(b, x);
    }
  } else if (s.useLdlt) {
    result = s.solveLdlt(b, x);
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
