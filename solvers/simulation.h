// A world being simulated: its model, its state and an integrator, stepped by dt, with
// divergence detected at the step it happens. The runner, the viewer and the experiments all
// drive a scene through this class.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "solvers/integrator.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world.h"

namespace jello {

// A state has diverged when any value is not finite or a point is farther than this from the
// origin (m): the box is [-2,2]^3, so no sane state comes near it.
inline constexpr double kDivergenceBound = 100.0;

// Why `state` is broken, or nothing when it is sane.
std::optional<std::string> findDivergence(const State& state, double bound = kDivergenceBound);

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

  // Switches the integrator, keeping the state.
  void setIntegrator(IntegratorKind kind);
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

  // The world with the current state as its initial state (what --out saves).
  World currentWorld() const;

 private:
  World world_;
  Model model_;
  State state_;
  State previous_;
  SolverOptions options_;
  std::unique_ptr<Integrator> integrator_;
  double dt_;
  long steps_ = 0;
  std::optional<Divergence> divergence_;
};

}  // namespace jello
