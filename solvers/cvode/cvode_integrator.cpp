#include "solvers/cvode/cvode_integrator.h"

#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <string>

#include "solvers/cvode/fast_nvector.h"
#include "src/base/interrupt.h"

namespace jello {
namespace {

CvodeIntegrator& self(void* data) {
  return *static_cast<CvodeIntegrator*>(data);
}

int rhsTrampoline(sunrealtype, N_Vector y, N_Vector ydot, void* data) {
  return self(data).rightHandSide(N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
}

// SUNDIALS' own messages: kept for our error message instead of printed raw to stderr.
void errorHandler(int code, const char* module, const char* function, char* message, void* data) {
  if (code >= 0) return;  // warnings: the statistics say what happened
  self(data).noteSundialsMessage(std::string(module ? module : "?") + "." +
                                 (function ? function : "?") + ": " + (message ? message : ""));
}

int rootTrampoline(sunrealtype, N_Vector y, sunrealtype* g, void* data) {
  return self(data).contactDepths(N_VGetArrayPointer(y), g);
}

int linsysTrampoline(sunrealtype, N_Vector y, N_Vector, SUNMatrix, sunbooleantype jok,
                     sunbooleantype* jcur, sunrealtype gamma, void* data, N_Vector, N_Vector,
                     N_Vector) {
  bool current = false;
  const int rc = self(data).linearSystem(N_VGetArrayPointer(y), jok != SUNFALSE, &current, gamma);
  *jcur = current ? SUNTRUE : SUNFALSE;
  return rc;
}

// SPGMR's preconditioner: when CVODE allows it (jok), the factor of the last setup is kept as it
// is, its gamma included (a preconditioner only needs to be near); otherwise the Jacobian is
// assembled at y and the reduced matrix formed and factored afresh.
int psetupTrampoline(sunrealtype, N_Vector y, N_Vector, sunbooleantype jok, sunbooleantype* jcur,
                     sunrealtype gamma, void* data) {
  CvodeIntegrator& integrator = self(data);
  if (jok != SUNFALSE && integrator.preconditionerReady()) {
    *jcur = SUNFALSE;
    return 0;
  }
  bool current = false;
  int rc = integrator.linearSystem(N_VGetArrayPointer(y), false, &current, gamma);
  *jcur = SUNTRUE;
  if (rc == 0) rc = integrator.setupSolver();
  integrator.setPreconditionerReady(rc == 0);
  return rc;
}
int psolveTrampoline(sunrealtype, N_Vector, N_Vector, N_Vector r, N_Vector z, sunrealtype,
                     sunrealtype, int, void* data) {
  return self(data).solve(N_VGetArrayPointer(r), N_VGetArrayPointer(z));
}

// The custom linear solver: its content is the integrator, which SUNDIALS must never free.
SUNLinearSolver_Type lsType(SUNLinearSolver) {
  return SUNLINEARSOLVER_DIRECT;
}
SUNLinearSolver_ID lsId(SUNLinearSolver) {
  return SUNLINEARSOLVER_CUSTOM;
}
int lsSetup(SUNLinearSolver s, SUNMatrix) {
  return self(s->content).setupSolver();
}
int lsSolve(SUNLinearSolver s, SUNMatrix, N_Vector x, N_Vector b, sunrealtype) {
  return self(s->content).solve(N_VGetArrayPointer(b), N_VGetArrayPointer(x));
}
int lsFree(SUNLinearSolver s) {
  s->content = nullptr;
  SUNLinSolFreeEmpty(s);
  return 0;
}

// The matrix CVODE hands around is a placeholder: the system lives in the integrator.
SUNMatrix_ID matId(SUNMatrix) {
  return SUNMATRIX_CUSTOM;
}
void matDestroy(SUNMatrix m) {
  SUNMatFreeEmpty(m);
}

std::string cvodeError(const char* call, int flag) {
  const char* name = CVodeGetReturnFlagName(flag);
  std::string text = std::string(call) + " failed: " + (name ? name : "unknown flag") + " (" +
                     std::to_string(flag) + ")";
  std::free(const_cast<char*>(name));  // CVodeGetReturnFlagName allocates its answer
  return text;
}

}  // namespace

CvodeIntegrator::CvodeIntegrator(CvodeOptions options)
    : options_(options), system_(options.linearSolverOptions(), options.clampCompression) {}

CvodeIntegrator::~CvodeIntegrator() {
  // CVODE first (it refers to the solvers, matrix and vectors), the context last.
  cvode_.reset();
  linearSolver_.reset();
  nonlinearSolver_.reset();
  atol_.reset();
  matrix_.reset();
  y_.reset();
  context_.reset();
}

bool CvodeIntegrator::continues(const Model& model, const State& s) const {
  if (restartPending_ || !cvode_ || modelId_ != model.id() || s.t != t_) return false;
  return s.x == lastX_ && s.v == lastV_;
}

namespace {

StepResult check(const char* call, int flag) {
  return flag == CV_SUCCESS ? StepResult::success() : StepResult::failure(cvodeError(call, flag));
}

}  // namespace

StepResult CvodeIntegrator::start(const Model& model, const State& s) {
  const bool sameModel = cvode_ && modelId_ == model.id();
  model_ = &model;
  modelId_ = model.id();
  n3_ = 3 * model.numPoints();
  if (!sameModel) {
    if (StepResult r = newContext(model); !r.ok) return r;
  }
  load(s);
  assembled_ = false;
  preconditionerReady_ = false;
  restartPending_ = false;
  ++restarts_;
  if (sameModel) {
    carryCounters();
    return check("CVodeReInit", CVodeReInit(cvode_.get(), s.t, y_.get()));
  }
  if (StepResult r = configure(s); !r.ok) return r;
  return attachSolvers();
}

StepResult CvodeIntegrator::newContext(const Model& model) {
  carryCounters();
  cvode_.reset();
  linearSolver_.reset();
  matrix_.reset();
  y_.reset();
  nonlinearSolver_.reset();
  atol_.reset();
  context_.reset();
  SUNContext ctx = nullptr;
  if (SUNContext_Create(nullptr, &ctx) != 0) return StepResult::failure("SUNContext_Create");
  context_.reset(ctx);
  y_.reset(N_VNew_Serial(2 * n3_, ctx));
  atol_.reset(N_VNew_Serial(2 * n3_, ctx));
  if (!y_ || !atol_) return StepResult::failure("N_VNew_Serial failed");
  // CVODE clones its work vectors from y_: they inherit the faster loops.
  if (options_.fastVectors &&
      (!installFastOperations(y_.get()) || !installFastOperations(atol_.get()))) {
    return StepResult::failure("the serial vectors' operations could not be replaced");
  }
  // A new model: the system rebuilds its pattern and its solver analyses afresh.
  system_.bind(model);
  b_.setZero(n3_);
  return StepResult::success();
}

void CvodeIntegrator::load(const State& s) {
  // Positions relative to the centre of mass of the start.
  const int n = n3_ / 3;
  shift_.resize(n3_);
  for (int c = 0; c < 3; ++c) shift_.segment(c * n, n).setConstant(s.x.segment(c * n, n).mean());
  double* y = N_VGetArrayPointer(y_.get());
  Eigen::Map<Eigen::VectorXd>(y, n3_) = s.x - shift_;
  Eigen::Map<Eigen::VectorXd>(y + n3_, n3_) = s.v;
  lastX_ = s.x;
  lastV_ = s.v;
  t_ = s.t;
}

// CVODE's memory with its tolerances, limits and root functions (every return code checked).
StepResult CvodeIntegrator::configure(const State& s) {
  const bool adams = options_.method == CvodeMethod::Adams;
  cvode_.reset(CVodeCreate(adams ? CV_ADAMS : CV_BDF, context_.get()));
  if (!cvode_) return StepResult::failure("CVodeCreate failed");
  void* mem = cvode_.get();
  if (int f = CVodeSetErrHandlerFn(mem, errorHandler, this); f != CV_SUCCESS) {
    return StepResult::failure(cvodeError("CVodeSetErrHandlerFn", f));
  }
  const double fallback = 1e-3 * options_.rtol;
  double* atol = N_VGetArrayPointer(atol_.get());
  std::fill(atol, atol + n3_, options_.atolPosition > 0.0 ? options_.atolPosition : fallback);
  std::fill(atol + n3_, atol + 2 * n3_,
            options_.atolVelocity > 0.0 ? options_.atolVelocity : fallback);
  for (const StepResult& r :
       {check("CVodeInit", CVodeInit(mem, rhsTrampoline, s.t, y_.get())),
        check("CVodeSVtolerances", CVodeSVtolerances(mem, options_.rtol, atol_.get())),
        check("CVodeSetUserData", CVodeSetUserData(mem, this)),
        check("CVodeSetMaxNumSteps", CVodeSetMaxNumSteps(mem, options_.maxStepsPerCall)),
        check("CVodeSetMaxOrd", CVodeSetMaxOrd(mem, options_.maxOrder)),
        check("CVodeSetMaxStep", CVodeSetMaxStep(mem, options_.maxStep))}) {
    if (!r.ok) return r;
  }
  if (!adams) {  // BDF only: CVODE refuses it for Adams
    const int flag = CVodeSetStabLimDet(mem, options_.stabilityLimitDetection ? SUNTRUE : SUNFALSE);
    if (StepResult r = check("CVodeSetStabLimDet", flag); !r.ok) return r;
  }
  if (options_.contactRoots && numRootFunctions() > 0) {
    return check("CVodeRootInit", CVodeRootInit(mem, numRootFunctions(), rootTrampoline));
  }
  return StepResult::success();
}

// Adams: fixed-point iterations. BDF: SPGMR preconditioned by the reduced system, or the
// reduced system solved exactly as a custom DIRECT solver (docs: dependencies.md's pitfalls).
StepResult CvodeIntegrator::attachSolvers() {
  void* mem = cvode_.get();
  if (options_.method == CvodeMethod::Adams) {
    nonlinearSolver_.reset(SUNNonlinSol_FixedPoint(y_.get(), 0, context_.get()));
    if (!nonlinearSolver_) return StepResult::failure("SUNNonlinSol_FixedPoint failed");
    return check("CVodeSetNonlinearSolver", CVodeSetNonlinearSolver(mem, nonlinearSolver_.get()));
  }
  if (usesKrylov()) {
    linearSolver_.reset(SUNLinSol_SPGMR(y_.get(), SUN_PREC_LEFT, 0, context_.get()));
    if (!linearSolver_) return StepResult::failure("SUNLinSol_SPGMR failed");
    if (StepResult r =
            check("CVodeSetLinearSolver", CVodeSetLinearSolver(mem, linearSolver_.get(), nullptr));
        !r.ok) {
      return r;
    }
    return check("CVodeSetPreconditioner",
                 CVodeSetPreconditioner(mem, psetupTrampoline, psolveTrampoline));
  }
  SUNMatrix A = SUNMatNewEmpty(context_.get());
  if (!A) return StepResult::failure("SUNMatNewEmpty failed");
  A->ops->getid = matId;
  A->ops->destroy = matDestroy;
  matrix_.reset(A);
  SUNLinearSolver ls = SUNLinSolNewEmpty(context_.get());
  if (!ls) return StepResult::failure("SUNLinSolNewEmpty failed");
  ls->content = this;
  ls->ops->gettype = lsType;
  ls->ops->getid = lsId;
  ls->ops->setup = lsSetup;
  ls->ops->solve = lsSolve;
  ls->ops->free = lsFree;
  linearSolver_.reset(ls);
  // The linear-system function after the solver: CVodeSetLinearSolver resets it.
  if (StepResult r = check("CVodeSetLinearSolver", CVodeSetLinearSolver(mem, ls, A)); !r.ok) {
    return r;
  }
  return check("CVodeSetLinSysFn", CVodeSetLinSysFn(mem, linsysTrampoline));
}

StepResult CvodeIntegrator::step(const Model& model, State& s, double h) {
  if (!continues(model, s)) {
    if (StepResult r = start(model, s); !r.ok) return r;
  }
  const double tout = s.t + h;
  sunrealtype reached = s.t;
  sundialsMessage_.clear();
  resourceFailure_.clear();
  for (;;) {
    const int flag = CVode(cvode_.get(), tout, y_.get(), &reached, CV_NORMAL);
    if (flag < 0 && interruptRequested()) {
      restartPending_ = true;  // CVODE's state is mid-step: start afresh if stepped again
      return StepResult::interruption();  // s is still the output interval's start
    }
    if (flag < 0 && !resourceFailure_.empty()) {
      restartPending_ = true;
      return StepResult::resourceFailure(resourceFailure_);
    }
    if (flag < 0) {
      std::string why = cvodeError("CVode", flag);
      if (!sundialsMessage_.empty()) why += " (" + sundialsMessage_ + ")";
      return StepResult::failure(why);
    }
    if (flag != CV_ROOT_RETURN || reached >= tout) break;
    // A contact began or ended at `reached`: the force's derivative jumps there, so the
    // history of the multistep method is restarted from the located state.
    ++roots_;
    carryCounters();
    if (int f = CVodeReInit(cvode_.get(), reached, y_.get()); f != CV_SUCCESS) {
      return StepResult::failure(cvodeError("CVodeReInit", f));
    }
  }
  const double* y = N_VGetArrayPointer(y_.get());
  s.x = Eigen::Map<const Eigen::VectorXd>(y, n3_) + shift_;
  s.v = Eigen::Map<const Eigen::VectorXd>(y + n3_, n3_);
  s.t = reached;
  t_ = reached;
  lastX_ = s.x;
  lastV_ = s.v;
  return StepResult::success();
}

int CvodeIntegrator::rightHandSide(const double* y, double* ydot) {
  // A stop requested inside a long output interval: an unrecoverable "failure" ends CVode()
  // at once, and step() reports it as an interruption.
  if (interruptRequested()) return -1;
  std::memcpy(ydot, y + n3_, static_cast<std::size_t>(n3_) * sizeof(double));
  x_ = Eigen::Map<const Eigen::VectorXd>(y, n3_) + shift_;
  model_->acceleration(x_.data(), y + n3_, ydot + n3_);
  double sum = 0.0;
  for (int i = n3_; i < 2 * n3_; ++i) sum += ydot[i];
  return std::isfinite(sum) ? 0 : 1;  // recoverable: CVODE retries with a smaller step
}

int CvodeIntegrator::linearSystem(const double* y, bool jacobianOk, bool* jacobianCurrent,
                                  double gamma) {
  if (!jacobianOk || !assembled_) {
    x_ = Eigen::Map<const Eigen::VectorXd>(y, n3_) + shift_;
    system_.assemble(x_.data(), y + n3_);
    assembled_ = true;
    *jacobianCurrent = true;
  }
  gamma_ = gamma;
  system_.formMatrix(gamma, gamma * gamma);  // M - g D - g^2 K
  return 0;
}

int CvodeIntegrator::setupSolver() {
  return linearSolverFlag(system_.factorize());
}

int CvodeIntegrator::solve(const double* b, double* x) {
  const Eigen::Map<const Eigen::VectorXd> r1(b, n3_), r2(b + n3_, n3_);
  rhs_.noalias() = system_.K() * r1;
  rhs_ = model_->mass() * r2 + gamma_ * rhs_;
  if (const int flag = linearSolverFlag(system_.solve(rhs_, b_)); flag != 0) return flag;
  Eigen::Map<Eigen::VectorXd>(x + n3_, n3_) = b_;
  Eigen::Map<Eigen::VectorXd>(x, n3_) = r1 + gamma_ * b_;
  return 0;
}

int CvodeIntegrator::numRootFunctions() const {
  int count = 0;
  for (const auto& obstacle : model_->obstacles()) count += obstacle->rootsPerPoint();
  return count * (n3_ / 3);
}

// Every obstacle's root functions (src/effects/obstacle.h): they change sign where a contact
// begins or ends, positive on the free side.
int CvodeIntegrator::contactDepths(const double* y, double* g) {
  const int n = n3_ / 3;
  x_ = Eigen::Map<const Eigen::VectorXd>(y, n3_) + shift_;
  for (const auto& obstacle : model_->obstacles()) {
    obstacle->roots(x_.data(), n, g);
    g += obstacle->rootsPerPoint() * n;
  }
  return 0;
}

namespace {

// CVODE's counters, which CVodeReInit sets back to zero: the integrator carries them over.
struct Counter {
  const char* name;
  int (*getter)(void*, long*);
};
constexpr Counter kCounters[] = {
    {"cvode_steps", CVodeGetNumSteps},
    {"rhs_evaluations", CVodeGetNumRhsEvals},
    {"linear_setups", CVodeGetNumLinSolvSetups},
    {"newton_iterations", CVodeGetNumNonlinSolvIters},
    {"newton_convergence_failures", CVodeGetNumNonlinSolvConvFails},
    {"error_test_failures", CVodeGetNumErrTestFails},
    // Krylov (SPGMR) only; zero otherwise, and left out.
    {"linear_iterations", CVodeGetNumLinIters},
    {"preconditioner_setups", CVodeGetNumPrecEvals},
    {"preconditioner_solves", CVodeGetNumPrecSolves},
    {"jtimes_rhs_evaluations", CVodeGetNumLinRhsEvals},
};
constexpr std::size_t kFirstKrylovCounter = 6;
static_assert(std::size(kCounters) == CvodeIntegrator::kNumCounters);

}  // namespace

void CvodeIntegrator::carryCounters() {
  if (!cvode_) return;
  for (std::size_t i = 0; i < kNumCounters; ++i) {
    if (i >= kFirstKrylovCounter && !usesKrylov()) continue;  // no linear-solver interface
    long value = 0;
    if (kCounters[i].getter(cvode_.get(), &value) == CV_SUCCESS) carried_[i] += value;
  }
}

std::vector<Statistic> CvodeIntegrator::statistics() const {
  std::vector<Statistic> stats;
  if (!cvode_) return stats;
  void* mem = cvode_.get();
  // Each getter's flag is checked; a figure whose getter fails is left out. The counts of
  // earlier starts (restarts, contact roots) are added.
  for (std::size_t i = 0; i < kNumCounters; ++i) {
    if (i >= kFirstKrylovCounter && !usesKrylov()) continue;
    long value = 0;
    if (kCounters[i].getter(mem, &value) == CV_SUCCESS) {
      stats.push_back({kCounters[i].name, static_cast<double>(value + carried_[i])});
    }
  }
  int order = 0;
  if (CVodeGetLastOrder(mem, &order) == CV_SUCCESS) stats.push_back({"last_order", double(order)});
  double lastStep = 0.0;
  if (CVodeGetLastStep(mem, &lastStep) == CV_SUCCESS) stats.push_back({"last_step_s", lastStep});
  stats.push_back({"starts", double(restarts_)});  // 1 + restarts from a state set outside
  if (options_.contactRoots) stats.push_back({"contact_roots", double(roots_)});
  system_.appendStatistics(stats);
  return stats;
}

}  // namespace jello
