#include "solvers/system/implicit_system.h"

#include <chrono>
#include <cmath>

#include "solvers/linalg/prefactored_cholesky.h"
#include "solvers/system/spring_laplacian.h"
#include "src/base/assertions.h"

namespace jello {
namespace {

// C of factorProjective at positions x (3n): b kc + a dc per contact spring a point has, over
// every obstacle.
void contactDiagonal(const Model& model, const double* x, double a, double b,
                     Eigen::VectorXd& out) {
  const int n = model.numPoints();
  out.setZero(n);
  for (const auto& obstacle : model.obstacles()) {
    const ContactConstants& k = obstacle->constants();
    const double w = b * k.stiffness + a * k.damping;
    for (int p = 0; p < n; ++p) out[p] += w * obstacle->contactSprings(pointAt(x, n, p));
  }
}

}  // namespace

ImplicitSystem::ImplicitSystem(const LinearSolverOptions& linearSolver, bool clampCompression,
                               bool directOperator)
    : clampCompression_(clampCompression),
      direct_(directOperator && linearSolver.kind == LinearSolverKind::Cg &&
              linearSolver.matrixFree && !preconditionerNeedsMatrix(linearSolver.preconditioner)),
      matrixFree_(linearSolver.kind == LinearSolverKind::Cg && linearSolver.matrixFree),
      solver_(linearSolver) {}

ImplicitSystem::~ImplicitSystem() = default;

bool ImplicitSystem::bind(const Model& model) {
  model_ = &model;
  if (model.id() == modelId_) return false;
  modelId_ = model.id();
  jacobian_ = std::make_unique<JacobianAssembler>(model);
  if (matrixFree_) operator_ = std::make_unique<SystemOperator>(model.springs(), model.numPoints());
  A_ = jacobian_->pattern();
  matricesStale_ = matrixStale_ = false;
  solver_.forgetPattern();
  laplacian_.reset();
  projective_.reset();
  projectiveA_ = projectiveB_ = -1.0;
  coarse_.reset();
  correctContacts_ = false;
  if (model.latticeResolution() >= kDefaultCoarseNodes) {
    coarse_ = std::make_unique<LatticeCoarseSpace>(model.latticeResolution(), kDefaultCoarseNodes);
  }
  return true;
}

void ImplicitSystem::assemble(const double* x, const double* v) {
  JELLO_ASSERT(bound(), "the implicit system is bound to a model before it assembles");
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Index n3 = 3 * static_cast<Eigen::Index>(model_->numPoints());
  JacobianOptions options{clampCompression_, false, v};
  options.includeSprings = !direct_;  // their blocks come from x at factorize()
  jacobian_->assemble(x, options);
  clamps_ += jacobian_->lastClampCount();
  if (direct_ || (solver_.kind() == LinearSolverKind::Cg &&
                  solver_.preconditioner() == PreconditionerKind::Projective)) {
    x_ = Eigen::Map<const Eigen::VectorXd>(x, n3);
  }
  if (direct_) {
    assembledClamp_ = clampCompression_;
    if (v) {
      v_ = Eigen::Map<const Eigen::VectorXd>(v, n3);
    } else {
      v_.resize(0);
    }
    matricesStale_ = matrixStale_ = true;
  }
  assembleSeconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void ImplicitSystem::formMatrix(double a, double b) {
  a_ = a;
  b_ = b;
  if (direct_) {
    matrixStale_ = true;
    return;
  }
  jacobian_->combine(a, b, A_);
}

void ImplicitSystem::formMatrices() {
  if (!matricesStale_) return;
  JacobianOptions options{assembledClamp_, false, v_.size() > 0 ? v_.data() : nullptr};
  jacobian_->assemble(x_.data(), options);  // its clamps were counted by the fill
  matricesStale_ = false;
}

const SparseMatrix& ImplicitSystem::K() {
  formMatrices();
  return jacobian_->K();
}

const SparseMatrix& ImplicitSystem::D() {
  formMatrices();
  return jacobian_->D();
}

const SparseMatrix& ImplicitSystem::A() {
  if (direct_ && matrixStale_) {
    formMatrices();
    jacobian_->combine(a_, b_, A_);
    matrixStale_ = false;
  }
  return A_;
}

double ImplicitSystem::dampingQuadratic(const Eigen::VectorXd& v) {
  if (!direct_ || !matricesStale_) {
    dv_.noalias() = D() * v;
    return v.dot(dv_);
  }
  const std::vector<double>& diagD = jacobian_->diagonalD();
  const Eigen::Index n = model_->numPoints();
  double sum = operator_->springDampingQuadratic(x_.data(), v.data());
  for (Eigen::Index p = 0; p < n; ++p) {
    const double* B = diagD.data() + 9 * p;
    const double u[3] = {v[p], v[n + p], v[2 * n + p]};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sum += u[r] * B[3 * r + c] * u[c];
  }
  return sum;
}

StepResult ImplicitSystem::factorize() {
  if (direct_) {
    const auto start = std::chrono::steady_clock::now();
    clamps_ += operator_->fill(x_.data(), model_->mass(), a_, b_, assembledClamp_,
                               jacobian_->diagonalK().data(), jacobian_->diagonalD().data());
    assembleSeconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  } else if (operator_) {
    operator_->gather(A_, jacobian_->diagonalSlots(), jacobian_->springSlots());
  }
  if (solver_.kind() == LinearSolverKind::Cg &&
      solver_.preconditioner() == PreconditionerKind::Projective) {
    contactDiagonal(*model_, x_.data(), a_, b_, contact_);
    if (!keepsProjective(contact_)) {
      if (StepResult res = factorProjective(a_, b_, &contact_); !res.ok) return res;
    }
  }
  if (direct_) return solver_.prepare(*operator_, A_.rows(), projective_.get());
  return solver_.factorize(A_, operator_.get(), projective_.get());
}

StepResult ImplicitSystem::factorize(double a, double b) {
  formMatrix(a, b);
  return factorize();
}

StepResult ImplicitSystem::factorProjective(double a, double b, const Eigen::VectorXd* contact) {
  JELLO_ASSERT(model_ && model_->id() == modelId_, "the projective matrix is for the bound model");
  const Model& model = *model_;
  const bool noContact = !contact || contact->isZero(0.0);
  const bool sameContact =
      noContact ? projectiveContact_.size() == 0
                : projectiveContact_.size() == contact->size() && projectiveContact_ == *contact;
  if (projective_ && projective_->factored() && a == projectiveA_ && b == projectiveB_ &&
      sameContact) {
    return StepResult::success();
  }
  if (!laplacian_) {
    laplacian_ = std::make_unique<SpringLaplacian>(model);
    projective_ = std::make_unique<PrefactoredCholesky>();
  }
  const auto start = std::chrono::steady_clock::now();
  laplacian_->form(model.mass(), a, b, noContact ? nullptr : contact->data(), projectiveMatrix_);
  StepResult result = projective_->factorize(projectiveMatrix_);
  projectiveSeconds_ +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++projectiveFactorizations_;
  if (!result.ok) {
    projectiveA_ = projectiveB_ = -1.0;
    return result.within("the projective matrix");
  }
  if (coarse_ && (a != projectiveA_ || b != projectiveB_)) {
    // The seeds' coarse space: P without C, for new coefficients.
    if (!noContact) laplacian_->form(model.mass(), a, b, nullptr, freeMatrix_);
    const SparseMatrix& free = noContact ? projectiveMatrix_ : freeMatrix_;
    coarse_->setBase(free);
  }
  projectiveA_ = a;
  projectiveB_ = b;
  if (noContact) {
    projectiveContact_.resize(0);
  } else {
    projectiveContact_ = *contact;
  }
  return StepResult::success();
}

// As a preconditioner, P may lack light contacts (or hold stale ones): it stays SPD and close
// to A, so CG converges as fast, and P is not refactored at each contact change.
bool ImplicitSystem::keepsProjective(const Eigen::VectorXd& contact) {
  if (!coarse_ || !projective_ || !projective_->factored() || a_ != projectiveA_ ||
      b_ != projectiveB_) {
    return false;
  }
  return lightAgainstFactor(contact, preconditionerDifference_);
}

bool ImplicitSystem::lightAgainstFactor(const Eigen::VectorXd& contact,
                                        Eigen::VectorXd& difference) const {
  difference = contact;
  if (projectiveContact_.size() > 0) difference -= projectiveContact_;
  return coarse_->light(difference);
}

StepResult ImplicitSystem::factorProjectiveForSeeds(double a, double b) {
  if (coarse_ && projective_ && projective_->factored() && a == projectiveA_ && b == projectiveB_) {
    return StepResult::success();
  }
  return factorProjective(a, b);
}

bool ImplicitSystem::lightContactsAt(const double* x) {
  JELLO_ASSERT(projective_ && projective_->factored(), "lightContactsAt follows factorProjective");
  const Model& model = *model_;
  correctContacts_ = false;
  // The barrier's stiffness has no bound and friction's tangential one is mu N/(eps_v h): the
  // seeds stop at their contacts, as they do without a lattice.
  if (!coarse_ || model.barrierContact() || model.hasFriction()) return !model.inContact(x);
  contactDiagonal(model, x, projectiveA_, projectiveB_, wantedContact_);
  if (!lightAgainstFactor(wantedContact_, contactDifference_)) return false;
  correctContacts_ = !contactDifference_.isZero(0.0);
  return true;
}

StepResult ImplicitSystem::correctProjective(Eigen::VectorXd& v) {
  if (!correctContacts_) return StepResult::success();
  const Eigen::Index n = contactDifference_.size();
  for (Eigen::Index c = 0; c < 3; ++c) {
    StepResult res = coarse_->correct(wantedContact_, contactDifference_.data(), v.data() + c * n);
    if (!res.ok) return res.within("the seeds' coarse correction");
  }
  return StepResult::success();
}

StepResult ImplicitSystem::solveProjective(Eigen::VectorXd& v) const {
  JELLO_ASSERT(projective_ && projective_->factored() && v.size() == 3 * projective_->size(),
               "solveProjective follows a successful factorProjective");
  return projective_->solve(v.data(), 3);
}

StepResult ImplicitSystem::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x,
                                 bool ldltFallback) {
  StepResult result = solver_.solve(rhs, x, ldltFallback);
  // Not positive definite (possible only with the clamp off): LDLT of A, formed now.
  if (!result.ok && direct_ && ldltFallback && solver_.indefinite()) {
    result = solver_.fallBackToLdlt(A(), rhs, x);
  }
  return result;
}

void ImplicitSystem::appendStatistics(std::vector<Statistic>& out) const {
  const LinearSolverStats& ls = solver_.stats();
  // Built in place: GCC 12 at -O3 calls moving a Statistic's long name out of bounds
  // (-Warray-bounds, a false positive of its string copy) when the standard headers come from
  // the precompiled header.
  const auto add = [&out](const char* name, double value) { out.emplace_back(name, value); };
  add("compression_clamps", static_cast<double>(clampCount()));
  add("factorizations", static_cast<double>(ls.factorizations));
  add("ldlt_fallbacks", static_cast<double>(ls.fallbacks));
  add("assemble_time_s", assembleSeconds_);
  add("factor_time_s", ls.factorSeconds);
  add("solve_time_s", ls.solveSeconds);
  if (projectiveFactorizations_ > 0) {
    add("projective_factorizations", static_cast<double>(projectiveFactorizations_));
    add("projective_factor_time_s", projectiveSeconds_);
  }
  if (solver_.kind() == LinearSolverKind::Cg) {
    add("cg_iterations", static_cast<double>(ls.cgIterations));
    // The preconditioners that factor a matrix (ichol, factor) say how often.
    if (ls.preconditionerFactorizations > 0) {
      add("preconditioner_factorizations", static_cast<double>(ls.preconditionerFactorizations));
    }
  }
}

}  // namespace jello
