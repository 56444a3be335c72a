// SUNDIALS CVODE (6.4), variable-order BDF with Newton iterations, on y = (x, v):
//   y' = (v, M^-1 f(x, v)),   Newton matrix I - g J,   J = [[0, I], [M^-1 K, M^-1 D]].
// Its linear systems (I - g J)(a, b) = (r1, r2) are solved through the reduced, symmetric
// 3n system (src/PHYSICS.md)
//   (M - g D - g^2 K) b = M r2 + g K r1,   a = r1 + g b,
// with the implicit integrators' own system (solvers/system/implicit_system.h), inside a
// custom linear solver of DIRECT type, so CVODE keeps its own heuristics for when to refresh
// the Jacobian and refactor, and its correction for a changed g. One step() call advances the
// state to t + h (an output interval), CVODE choosing its own internal steps.
// Method adams: Adams-Moulton with fixed-point iterations (SUNNonlinSol_FixedPoint), for the
// non-stiff regime: no Jacobian, no linear solves.
// CVODE integrates the positions relative to the cube's centre of mass at the start (so its
// relative tolerance does not depend on where the scene is), with separate absolute
// tolerances for positions and velocities (CVodeSVtolerances). With contactRoots, the
// penetration depths (walls: 2 - |x_i| per coordinate; plane: signed distance; sphere:
// distance - R; cone: signed distance; spiral: its face depths, src/effects/obstacles.h) are
// CVODE root functions: it stops where a contact begins or ends, and is
// restarted there (CVodeReInit), as the force's derivative jumps.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "solvers/cvode/sundials_handles.h"
#include "solvers/integrator.h"
#include "solvers/system/implicit_system.h"

namespace jello {

class CvodeIntegrator final : public Integrator {
 public:
  explicit CvodeIntegrator(CvodeOptions options = {});
  explicit CvodeIntegrator(const SolverOptions& options) : CvodeIntegrator(options.cvode) {}
  ~CvodeIntegrator() override;

  IntegratorKind kind() const override { return IntegratorKind::Cvode; }
  StepResult step(const Model& model, State& state, double h) override;
  std::vector<Statistic> statistics() const override;
  void restart() override { restartPending_ = true; }

  // The callbacks' work (public for the C trampolines in the .cpp).
  int rightHandSide(const double* y, double* ydot);
  int linearSystem(const double* y, bool jacobianOk, bool* jacobianCurrent, double gamma);
  // BDF with SPGMR (CvodeOptions::krylov): Adams has no linear solver.
  bool usesKrylov() const { return options_.krylov && options_.method == CvodeMethod::Bdf; }
  bool preconditionerReady() const { return preconditionerReady_; }
  void setPreconditionerReady(bool ready) { preconditionerReady_ = ready; }
  int setupSolver();
  int solve(const double* b, double* x);
  int contactDepths(const double* y, double* g);
  void noteSundialsMessage(std::string message) { sundialsMessage_ = std::move(message); }
  int numRootFunctions() const;

  static constexpr std::size_t kNumCounters = 10;

 private:
  // (Re)starts CVODE at `state`: a new model gets a new context, vectors and memory
  // (newContext, then configure and attachSolvers), the same one a CVodeReInit.
  StepResult start(const Model& model, const State& state);
  StepResult newContext(const Model& model);
  void load(const State& state);  // y = (x - the centre of mass at the start, v)
  StepResult configure(const State& state);
  StepResult attachSolvers();
  bool continues(const Model& model, const State& state) const;
  // Adds CVODE's counters to carried_ before CVodeReInit or a new CVODE zeroes them.
  void carryCounters();

  CvodeOptions options_;
  const Model* model_ = nullptr;  // for the callbacks, during a step
  long modelId_ = -1;             // the model bound to (Model::id, never its address)
  int n3_ = 0;                    // 3n
  sundials::Context context_;
  sundials::Vector y_;
  sundials::Matrix matrix_;
  sundials::LinearSolver linearSolver_;
  sundials::NonlinearSolver nonlinearSolver_;  // adams: fixed point
  sundials::Vector atol_;
  sundials::CvodeMemory cvode_;
  ImplicitSystem system_;
  double gamma_ = 0.0;  // of the matrix last formed
  bool assembled_ = false;
  Eigen::VectorXd rhs_, b_;
  Eigen::VectorXd shift_;  // 3n: the start's centre of mass, added back to CVODE's positions
  Eigen::VectorXd x_;      // 3n: absolute positions for the callbacks
  Eigen::VectorXd lastX_, lastV_;  // the state last handed out, to notice changes from outside
  double t_ = 0.0;                 // CVODE's time, to notice a state changed from outside
  long restarts_ = 0, roots_ = 0;
  bool preconditionerReady_ = false;  // krylov: a factor from an earlier setup is there
  std::array<long, kNumCounters> carried_{};
  std::string sundialsMessage_;  // SUNDIALS' last error message, for ours
  // A linear solver that could not run here (StepResult::resource): the callback returns an
  // unrecoverable -1 and step() reports this instead of CVODE's failure.
  std::string resourceFailure_;
  int linearSolverFlag(const StepResult& r) {
    if (r.ok) return 0;
    if (!r.resource) return 1;  // recoverable: CVODE retries with a smaller step
    resourceFailure_ = r.message;
    return -1;
  }
  bool restartPending_ = false;  // the model's forces changed from outside
};

}  // namespace jello
