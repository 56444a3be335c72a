#include "solvers/simulation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "src/assertions.h"
#include "src/integrator_name.h"

namespace jello {

namespace {

// The largest |(a_p, b_p, c_p)| over points p of a component-major 3n vector.
double largestNorm(const Eigen::VectorXd& v) {
  const Eigen::Index n = v.size() / 3;
  return (v.head(n).array().square() + v.segment(n, n).array().square() +
          v.tail(n).array().square())
      .maxCoeff();
}

}  // namespace

std::optional<std::string> findDivergence(const State& s, double bound, double speedBound) {
  // A sum propagates any NaN or infinity; one pass each, both vectorize.
  if (!std::isfinite(s.x.sum() + s.v.sum())) {
    return std::string("a position or velocity is not finite");
  }
  if (s.x.size() == 0) return std::nullopt;
  if (const double far = std::sqrt(largestNorm(s.x)); far > bound) {
    std::ostringstream os;
    os << "a point is " << far << " m from the origin (position bound " << bound << " m)";
    return os.str();
  }
  if (const double fast = std::sqrt(largestNorm(s.v)); fast > speedBound) {
    std::ostringstream os;
    os << "a point moves at " << fast << " m/s (speed bound " << speedBound << " m/s)";
    return os.str();
  }
  return std::nullopt;
}

double Simulation::energyBudget() const {
  return kEnergyGrowthFactor * energyEnvelope_ + kEnergyFloor;
}

std::optional<std::string> Simulation::energyGrowth() {
  const double now = model_.energy(state_).total() - externalWork();
  const bool swings = isExplicit(integrator_->kind());
  if (swings && steps_ - envelopeStart_ <= kEnergyEnvelopeSteps) {
    energyEnvelope_ = std::max(energyEnvelope_, now);
    return std::nullopt;
  }
  if (now <= energyBudget()) return std::nullopt;
  std::ostringstream os;
  os << "the energy grew to " << now << " J (energy bound " << kEnergyGrowthFactor << " x its "
     << (swings ? "envelope " : "start's ") << energyEnvelope_ << " J";
  if (swings) os << ", the largest of its first " << kEnergyEnvelopeSteps << " steps";
  os << ", + " << kEnergyFloor << " J, net of the field's and the user force's work)";
  return os.str();
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
      dt_(dt.value_or(world_.dt)),
      energyEnvelope_(std::max(0.0, model_.energy(state_).total())) {}

StepResult Simulation::step() {
  if (divergence_) return StepResult::failure(divergence_->describe());
  JELLO_VALIDATE(std::isfinite(state_.x.sum() + state_.v.sum()),
                 "the state handed to a step is finite");
  previous_ = state_;
  StepResult result = integrator_->step(model_, state_, dt_);
  if (result.resource) {
    // Nothing diverged: the step could not run here (a resource limit); the state is its start.
    state_ = previous_;
    integrator_->restart();
    std::ostringstream os;
    os << "stopped at t = " << state_.t << " s, step " << steps_ + 1 << ", integrator "
       << integratorName(integrator_->kind()) << ": " << result.message;
    result.message = os.str();
    return result;
  }
  if (result.interrupted) {
    // Asked to stop inside the step: nothing diverged; the state is the step's start, and the
    // integrator starts afresh if stepped again (its step was cut short).
    state_ = previous_;
    integrator_->restart();
    return result;
  }
  // The speed at which one point alone would hold the whole energy budget.
  const double speedBound =
      std::sqrt(2.0 * (energyBudget() + std::max(0.0, externalWork())) / model_.mass());
  std::optional<std::string> broken = result.ok
                                          ? findDivergence(state_, kDivergenceBound, speedBound)
                                          : std::optional<std::string>(result.message);
  ++steps_;
  if (!broken) {
    // The work of the forces no potential describes, only for scenes that have them.
    if (model_.hasField()) fieldWork_ += model_.fieldWork(previous_.x.data(), state_.x.data());
    if (model_.hasUserForce()) userWork_ += model_.userForceWork(previous_.x, state_.x);
    if (steps_ - envelopeStart_ <= kEnergyEnvelopeSteps || steps_ % kEnergyCheckInterval == 0) {
      broken = energyGrowth();
    }
  }
  if (!broken) return result;
  state_ = previous_;
  divergence_ = Divergence{state_.t, steps_, integrator_->kind(), *broken};
  return StepResult::failure(divergence_->describe());
}

void Simulation::setIntegrator(IntegratorKind kind) {
  if (kind != integrator_->kind()) integrator_ = makeIntegrator(kind, options_);
}

void Simulation::setIntegrator(IntegratorKind kind, const SolverOptions& options) {
  options_ = options;
  integrator_ = makeIntegrator(kind, options_);
}

void Simulation::stateEdited() {
  JELLO_ASSERT(state_.x.size() == 3 * model_.numPoints() && state_.v.size() == state_.x.size(),
               "an edited state keeps its size");
  integrator_->restart();
  if (divergence_ && !findDivergence(state_)) divergence_.reset();
  energyEnvelope_ = std::max(0.0, model_.energy(state_).total() - externalWork());
  envelopeStart_ = steps_;
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
