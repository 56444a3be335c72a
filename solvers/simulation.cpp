#include "solvers/simulation.h"

#include <cmath>
#include <sstream>

#include "src/assertions.h"

namespace jello {

std::optional<std::string> findDivergence(const State& s, double bound) {
  // A sum propagates any NaN or infinity; one pass each, both vectorize.
  if (!std::isfinite(s.x.sum() + s.v.sum())) {
    return std::string("a position or velocity is not finite");
  }
  const double far = s.x.cwiseAbs().maxCoeff();
  if (far > bound) {
    std::ostringstream os;
    os << "a point is " << far << " m from the origin (bound " << bound << " m)";
    return os.str();
  }
  return std::nullopt;
}

std::string Divergence::describe() const {
  std::ostringstream os;
  os << "diverged at t = " << time << " s, step " << step << ", integrator "
     << integratorName(integrator) << ": " << reason;
  return os.str();
}

Simulation::Simulation(World world, std::optional<IntegratorKind> integrator,
                       std::optional<double> dt, SolverOptions options)
    : world_(std::move(world)),
      model_(world_),
      state_(initialState(world_)),
      options_(options),
      integrator_(makeIntegrator(integrator.value_or(world_.integrator), options_)),
      dt_(dt.value_or(world_.dt)) {}

StepResult Simulation::step() {
  if (divergence_) return StepResult::failure(divergence_->describe());
  JELLO_VALIDATE(std::isfinite(state_.x.sum() + state_.v.sum()),
                 "the state handed to a step is finite");
  previous_ = state_;
  StepResult result = integrator_->step(model_, state_, dt_);
  std::optional<std::string> broken =
      result.ok ? findDivergence(state_) : std::optional<std::string>(result.message);
  ++steps_;
  if (!broken) return result;
  state_ = previous_;
  divergence_ = Divergence{state_.t, steps_, integrator_->kind(), *broken};
  return StepResult::failure(divergence_->describe());
}

void Simulation::setIntegrator(IntegratorKind kind) {
  if (kind != integrator_->kind()) integrator_ = makeIntegrator(kind, options_);
}

void Simulation::setTimeStep(double dt) {
  dt_ = dt;
}

void Simulation::setUserForce(const Eigen::VectorXd& f) {
  model_.setUserForce(f);
  integrator_->restart();
}

void Simulation::clearUserForce() {
  if (!model_.hasUserForce()) return;
  model_.clearUserForce();
  integrator_->restart();
}

World Simulation::currentWorld() const {
  World w = world_;
  storeState(state_, w);
  w.integrator = integrator_->kind();
  w.dt = dt_;
  return w;
}

}  // namespace jello
