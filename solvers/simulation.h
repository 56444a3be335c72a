// A world being simulated: its model, its state and an integrator, stepped by dt, with
// divergence detected at the step it happens. The runner, the viewer and the experiments all
// drive a scene through this class.
#pragma once

#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "solvers/integrator.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/world.h"

namespace jello {

// A state has diverged when any value is not finite or a point is farther than
// kDivergenceBound from the origin (m: the box is [-2,2]^3, so no sane state comes near it).
inline constexpr double kDivergenceBound = kStartBound;
// A run has diverged, too, when its energy has grown: kinetic + spring + contact energy minus
// the work the field, the user force and friction have done exceeds the budget,
// kEnergyGrowthFactor times its envelope plus kEnergyFloor (J, so that a cube starting at rest
// is not flagged by round-off) plus kWorkUncertainty of the work the field and the user force
// did: the stability experiment's blow-up rule (which has no user force, and its own envelope).
// The envelope is the start's energy, except for symplectic and forward Euler (energySwings):
// the largest energy of their first kEnergyEnvelopeSteps steps (from the start or an edit), as a
// bounded oscillation's energy swings within its first periods (symplectic Euler's by
// 1/(1 - h w/2) near h w = 2, 20x at h w = 1.9) and never beyond, while an unstable mode's keeps
// growing. 16 steps hold five periods of a mode at h w = 2 (a slower mode swings less: at most
// 2.3x once its period passes 8 steps). RK4 has no swing to wait out: on a linear mode it
// multiplies the amplitude by |R(i h w)| <= 1 up to its limit, so its energy never rises (an
// envelope let RK4 just past its limit, stiff-k1e4.w at dt 3.3e-4, take a 9x growth in and end a
// 50-step run at 70x its start unflagged). Nor have the implicit methods (Newmark on the
// spinning stiff cube at dt = 0.01 gained 22x in its first converged step and 800x over 20 s
// unflagged while an envelope of 64 steps took the growth in). The energy is checked at every
// one of the first kEnergyEnvelopeSteps steps, then every kEnergyCheckInterval steps (it costs
// about one force evaluation), and at a run's end (checkEnergy); at every step, a point whose
// own kinetic energy exceeds the budget (a speed bound, sqrt(2 budget/m)) is caught.
inline constexpr double kEnergyGrowthFactor = 10.0;
inline constexpr double kEnergyFloor = 1.0;
// The field's and the user force's work is the trapezoid rule along each step (Model::fieldWork),
// which an integrator's own update matches only to O(h): implicit-linear, a cube pushed from rest
// by a radial field (190 J of work in 0.07 s), gained 1.8 J over it while within 0.005 m of RK4.
// The budget allows this fraction of the work they did, step by step in absolute value.
inline constexpr double kWorkUncertainty = 0.05;
inline constexpr long kEnergyCheckInterval = 16;
inline constexpr long kEnergyEnvelopeSteps = 16;

// Whether the method's energy swings above its start on a bounded oscillation (the energy rule
// then measures against an envelope, not the start).
bool energySwings(IntegratorKind kind);

// Why `state` is broken, or nothing when it is sane (not finite, too far, faster than
// speedBound m/s; which bound fired is in the text).
std::optional<std::string> findDivergence(
    const State& state, double bound = kDivergenceBound,
    double speedBound = std::numeric_limits<double>::infinity());

struct Divergence {
  double time = 0.0;  // s, simulated time of the last sane state
  long step = 0;      // the step that produced the broken state (1-based)
  IntegratorKind integrator = IntegratorKind::RK4;
  std::string reason;

  std::string describe() const;
};

class Simulation {
 public:
  // The world's own integrator and dt unless overridden.
  explicit Simulation(World world, std::optional<IntegratorKind> integrator = std::nullopt,
                      std::optional<double> dt = std::nullopt, SolverOptions options = {});

  // One step of dt. On failure (divergence, or a solver's own failure) the state keeps the last
  // sane values and every further call fails the same way.
  StepResult step();
  // The energy rule at the current state, whatever the step count: a run's last state, which the
  // rule would otherwise see only at its next multiple of kEnergyCheckInterval steps. A growth
  // past the budget is a divergence at the last step, as step() reports it (the state goes back
  // one step); within the envelope's first steps there is nothing to judge against yet.
  StepResult checkEnergy();

  // Switches the integrator, keeping the state.
  void setIntegrator(IntegratorKind kind);
  // The same with other solver options (a new integrator even when the kind is the same).
  void setIntegrator(IntegratorKind kind, const SolverOptions& options);
  // The state, for editing in place (the Python module's numpy views write into it). Its
  // vectors must keep their size. Call stateEdited() after a change, before the next step.
  State& editableState() {
    verified_ = false;
    return state_;
  }
  // The state was changed from outside: the integrator starts afresh (no history, as after a
  // user force), the energy rule takes the new energy as its start, and a divergence is
  // forgotten when the state is sane again.
  void stateEdited();
  void setTimeStep(double dt);
  // A force from outside the world (the viewer's drag), N per point, 3n component-major;
  // cleared with clearUserForce.
  void setUserForce(const Eigen::VectorXd& f);
  void clearUserForce();

  const World& world() const { return world_; }
  const Model& model() const { return model_; }
  const Integrator& integrator() const { return *integrator_; }
  IntegratorKind integratorKind() const { return integrator_->kind(); }
  const State& state() const { return state_; }
  double dt() const { return dt_; }
  long steps() const { return steps_; }
  const std::optional<Divergence>& divergence() const { return divergence_; }
  const SolverOptions& solverOptions() const { return options_; }
  // Work (J) the force field and the user force have done on the points since the start, by
  // the trapezoid rule along each step (Model::fieldWork): minus it is their share of the
  // energy balance, so kinetic + spring + contact - work is what damping alone changes.
  double fieldWork() const { return fieldWork_; }
  double userForceWork() const { return userWork_; }
  // Work (J, <= 0) friction has done since the start (Model::frictionWork, step by step): minus
  // it is what friction dissipated, which the energy rule counts beside the energy, so an
  // integrator's gain is not hidden by friction's loss.
  double frictionWork() const { return frictionWork_; }

  // The world with the current state as its initial state (what --out saves).
  World currentWorld() const;

  // Keep the least signed distance of any point to any solid (Model::minObstacleDistance) over
  // the states from now on, the current one included: negative, the deepest penetration.
  void trackObstacleDistance();
  // That least distance (m), or nothing when not tracked or the scene has no solid.
  std::optional<double> minObstacleDistance() const;

 private:
  World world_;
  Model model_;
  State state_;
  State previous_;
  bool verified_ = false;  // state_ was checked finite and has not been handed out since
  SolverOptions options_;
  std::unique_ptr<Integrator> integrator_;
  double dt_;
  long steps_ = 0;
  std::optional<Divergence> divergence_;
  // The energy rule: the envelope (the largest energy net of external work in the first
  // kEnergyEnvelopeSteps steps since envelopeStart_), and the work done by the field and the
  // user force.
  double energyEnvelope_ = 0.0;
  long envelopeStart_ = 0;
  double fieldWork_ = 0.0;
  double userWork_ = 0.0;
  double workMoved_ = 0.0;  // the sum of |their work| over the steps since envelopeStart_
  double frictionWork_ = 0.0;
  bool trackDistance_ = false;
  double minDistance_ = 0.0;
  double externalWork() const { return fieldWork_ + userWork_ + frictionWork_; }
  std::optional<std::string> energyGrowth();
  // The work the field, the user force and friction did over the last step (previous_ to
  // state_), added to their sums.
  void addStepWork();
  // The run diverged at the last step: the state goes back to the step's start.
  StepResult diverged(const std::string& reason);
  // The barrier's rule (no point at or inside a solid) and the tracked least distance.
  std::optional<std::string> obstacleDistance();
  double energyBudget() const;
};

}  // namespace jello
