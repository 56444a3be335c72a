#include "solvers/cvode_integrator.h"

#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>

#include <cmath>
#include <cstring>
#include <string>

namespace jello {
namespace {

CvodeIntegrator& self(void* data) {
  return *static_cast<CvodeIntegrator*>(data);
}

int rhsTrampoline(sunrealtype, N_Vector y, N_Vector ydot, void* data) {
  return self(data).rightHandSide(N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
}

int linsysTrampoline(sunrealtype, N_Vector y, N_Vector, SUNMatrix, sunbooleantype jok,
                     sunbooleantype* jcur, sunrealtype gamma, void* data, N_Vector, N_Vector,
                     N_Vector) {
  bool current = false;
  const int rc = self(data).linearSystem(N_VGetArrayPointer(y), jok != SUNFALSE, &current, gamma);
  *jcur = current ? SUNTRUE : SUNFALSE;
  return rc;
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
    : options_(options),
      system_(options.linearSolver, options.cgTolerance, options.clampCompression) {}

CvodeIntegrator::~CvodeIntegrator() {
  // CVODE first (it refers to the solver, matrix and vector), the context last.
  cvode_.reset();
  linearSolver_.reset();
  matrix_.reset();
  y_.reset();
  context_.reset();
}

bool CvodeIntegrator::continues(const Model& model, const State& s) const {
  if (restartPending_ || !cvode_ || modelId_ != model.id() || s.t != t_) return false;
  const double* y = N_VGetArrayPointer(y_.get());
  const std::size_t bytes = static_cast<std::size_t>(n3_) * sizeof(double);
  return std::memcmp(y, s.x.data(), bytes) == 0 && std::memcmp(y + n3_, s.v.data(), bytes) == 0;
}

StepResult CvodeIntegrator::start(const Model& model, const State& s) {
  const bool sameModel = cvode_ && modelId_ == model.id();
  model_ = &model;
  modelId_ = model.id();
  n3_ = 3 * model.numPoints();
  if (!sameModel) {
    cvode_.reset();
    linearSolver_.reset();
    matrix_.reset();
    y_.reset();
    context_.reset();
    SUNContext ctx = nullptr;
    if (SUNContext_Create(nullptr, &ctx) != 0) return StepResult::failure("SUNContext_Create");
    context_.reset(ctx);
    y_.reset(N_VNew_Serial(2 * n3_, ctx));
    if (!y_) return StepResult::failure("N_VNew_Serial failed");
    // A new model: the system rebuilds its pattern and its solver analyses afresh.
    system_.bind(model);
    b_.setZero(n3_);
  }
  double* y = N_VGetArrayPointer(y_.get());
  std::memcpy(y, s.x.data(), static_cast<std::size_t>(n3_) * sizeof(double));
  std::memcpy(y + n3_, s.v.data(), static_cast<std::size_t>(n3_) * sizeof(double));
  t_ = s.t;
  assembled_ = false;
  restartPending_ = false;
  ++restarts_;

  if (sameModel) {
    if (int f = CVodeReInit(cvode_.get(), s.t, y_.get()); f != CV_SUCCESS) {
      return StepResult::failure(cvodeError("CVodeReInit", f));
    }
    return StepResult::success();
  }
  cvode_.reset(CVodeCreate(CV_BDF, context_.get()));
  if (!cvode_) return StepResult::failure("CVodeCreate failed");
  void* mem = cvode_.get();
  const double atol = options_.atol > 0.0 ? options_.atol : 1e-3 * options_.rtol;
  auto check = [](const char* call, int flag) {
    return flag == CV_SUCCESS ? StepResult::success() : StepResult::failure(cvodeError(call, flag));
  };
  for (const StepResult& r :
       {check("CVodeInit", CVodeInit(mem, rhsTrampoline, s.t, y_.get())),
        check("CVodeSStolerances", CVodeSStolerances(mem, options_.rtol, atol)),
        check("CVodeSetUserData", CVodeSetUserData(mem, this)),
        check("CVodeSetMaxNumSteps", CVodeSetMaxNumSteps(mem, options_.maxStepsPerCall)),
        check("CVodeSetMaxOrd", CVodeSetMaxOrd(mem, options_.maxOrder)),
        check("CVodeSetStabLimDet",
              CVodeSetStabLimDet(mem, options_.stabilityLimitDetection ? SUNTRUE : SUNFALSE)),
        check("CVodeSetMaxStep", CVodeSetMaxStep(mem, options_.maxStep))}) {
    if (!r.ok) return r;
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
  sunrealtype reached = s.t;
  const int flag = CVode(cvode_.get(), s.t + h, y_.get(), &reached, CV_NORMAL);
  if (flag < 0) return StepResult::failure(cvodeError("CVode", flag));
  const double* y = N_VGetArrayPointer(y_.get());
  std::memcpy(s.x.data(), y, static_cast<std::size_t>(n3_) * sizeof(double));
  std::memcpy(s.v.data(), y + n3_, static_cast<std::size_t>(n3_) * sizeof(double));
  s.t = reached;
  t_ = reached;
  return StepResult::success();
}

int CvodeIntegrator::rightHandSide(const double* y, double* ydot) {
  std::memcpy(ydot, y + n3_, static_cast<std::size_t>(n3_) * sizeof(double));
  model_->acceleration(y, y + n3_, ydot + n3_);
  double sum = 0.0;
  for (int i = n3_; i < 2 * n3_; ++i) sum += ydot[i];
  return std::isfinite(sum) ? 0 : 1;  // recoverable: CVODE retries with a smaller step
}

int CvodeIntegrator::linearSystem(const double* y, bool jacobianOk, bool* jacobianCurrent,
                                  double gamma) {
  if (!jacobianOk || !assembled_) {
    system_.assemble(y);
    assembled_ = true;
    *jacobianCurrent = true;
  }
  gamma_ = gamma;
  system_.formMatrix(gamma, gamma * gamma);  // M - g D - g^2 K
  return 0;
}

int CvodeIntegrator::setupSolver() {
  return system_.factorize().ok ? 0 : 1;
}

int CvodeIntegrator::solve(const double* b, double* x) {
  const Eigen::Map<const Eigen::VectorXd> r1(b, n3_), r2(b + n3_, n3_);
  rhs_.noalias() = system_.K() * r1;
  rhs_ = model_->mass() * r2 + gamma_ * rhs_;
  if (!system_.solve(rhs_, b_).ok) return 1;
  Eigen::Map<Eigen::VectorXd>(x + n3_, n3_) = b_;
  Eigen::Map<Eigen::VectorXd>(x, n3_) = r1 + gamma_ * b_;
  return 0;
}

std::vector<Statistic> CvodeIntegrator::statistics() const {
  std::vector<Statistic> stats;
  if (!cvode_) return stats;
  void* mem = cvode_.get();
  // Each getter's flag is checked; a figure whose getter fails is left out.
  auto add = [&](const char* name, int (*getter)(void*, long*)) {
    long value = 0;
    if (getter(mem, &value) == CV_SUCCESS) stats.push_back({name, static_cast<double>(value)});
  };
  add("cvode_steps", CVodeGetNumSteps);
  add("rhs_evaluations", CVodeGetNumRhsEvals);
  add("linear_setups", CVodeGetNumLinSolvSetups);
  add("newton_iterations", CVodeGetNumNonlinSolvIters);
  add("newton_convergence_failures", CVodeGetNumNonlinSolvConvFails);
  add("error_test_failures", CVodeGetNumErrTestFails);
  int order = 0;
  if (CVodeGetLastOrder(mem, &order) == CV_SUCCESS) stats.push_back({"last_order", double(order)});
  stats.push_back({"starts", double(restarts_)});  // 1 + restarts from a state set outside
  system_.appendStatistics(stats);
  return stats;
}

}  // namespace jello
