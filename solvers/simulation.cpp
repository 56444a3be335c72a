#include "solvers/simulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <sstream>

#include "solvers/integrator_factory.h"
#include "src/base/assertions.h"
#include "src/base/parallel.h"
#include "src/world/integrator_table.h"

namespace jello {

namespace {

// What findDivergence looks at, over some points: the sum of their coordinates and velocities
// (any NaN or infinity makes it one) and their largest squared distance from the origin and
// squared speed.
struct StateScan {
  double sum = 0.0, far2 = 0.0, fast2 = 0.0;
  void add(const StateScan& o) {
    sum += o.sum;
    far2 = std::max(far2, o.far2);
    fast2 = std::max(fast2, o.fast2);
  }
};

// The points [lo, hi) in one vectorized pass.
StateScan scanPoints(const State& s, std::ptrdiff_t lo, std::ptrdiff_t hi) {
  const std::ptrdiff_t n = s.x.size() / 3;
  const double *x = s.x.data(), *v = s.v.data();
  double sum = 0.0, far2 = 0.0, fast2 = 0.0;
#pragma omp simd reduction(+ : sum) reduction(max : far2, fast2)
  for (std::ptrdiff_t p = lo; p < hi; ++p) {
    const double x0 = x[p], x1 = x[n + p], x2 = x[2 * n + p];
    const double v0 = v[p], v1 = v[n + p], v2 = v[2 * n + p];
    sum += (x0 + x1 + x2) + (v0 + v1 + v2);
    far2 = std::max(far2, x0 * x0 + x1 * x1 + x2 * x2);
    fast2 = std::max(fast2, v0 * v0 + v1 * v1 + v2 * v2);
  }
  return {sum, far2, fast2};
}

std::optional<std::string> describeDivergence(const StateScan& scan, double bound,
                                              double speedBound) {
  if (!std::isfinite(scan.sum)) return std::string("a position or velocity is not finite");
  if (const double far = std::sqrt(scan.far2); far > bound) {
    std::ostringstream os;
    os << "a point is " << far << " m from the origin (position bound " << bound << " m)";
    return os.str();
  }
  if (const double fast = std::sqrt(scan.fast2); fast > speedBound) {
    std::ostringstream os;
    os << "a point moves at " << fast << " m/s (speed bound " << speedBound << " m/s)";
    return os.str();
  }
  return std::nullopt;
}

}  // namespace

bool energySwings(IntegratorKind kind) {
  return kind == IntegratorKind::Symplectic || kind == IntegratorKind::Euler;
}

std::optional<std::string> findDivergence(const State& s, double bound, double speedBound) {
  return describeDivergence(scanPoints(s, 0, s.x.size() / 3), bound, speedBound);
}

double Simulation::energyBudget() const {
  return kEnergyGrowthFactor * energyEnvelope_ + kEnergyFloor + kWorkUncertainty * workMoved_;
}

std::optional<std::string> Simulation::energyGrowth() {
  const double now = model_.energy(state_).total() - externalWork();
  const bool swings = energySwings(integrator_->kind());
  if (swings && steps_ - envelopeStart_ <= kEnergyEnvelopeSteps) {
    energyEnvelope_ = std::max(energyEnvelope_, now);
    return std::nullopt;
  }
  if (now <= energyBudget()) return std::nullopt;
  std::ostringstream os;
  os << "the energy grew to " << now << " J (energy bound " << kEnergyGrowthFactor << " x its "
     << (swings ? "envelope " : "start's ") << energyEnvelope_ << " J";
  if (swings) os << ", the largest of its first " << kEnergyEnvelopeSteps << " steps";
  os << ", + " << kEnergyFloor << " J";
  if (workMoved_ > 0.0) {
    os << " + " << kWorkUncertainty << " x the " << workMoved_
       << " J of work the field and the user force did";
  }
  os << ", net of the field's, the user force's and friction's work)";
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
  if (!verified_) {  // else the last step's divergence check saw it finite
    JELLO_VALIDATE(std::isfinite(state_.x.sum() + state_.v.sum()),
                   "the state handed to a step is finite");
    // A barrier scene must start outside every solid, every start finite (callers say so
    // before stepping).
    if (const std::optional<StartProblem> why = model_.startProblem(state_)) {
      return StepResult::failure(why->message);
    }
    verified_ = true;
  }
  // previous_ = state_, and below the divergence check, on the threads the model splits its
  // points over, each on its own points: on one thread these passes would be serial and read
  // what the other core wrote in the step (the blocks are those RK4's updates run on).
  const PointBlocks blocks = model_.pointBlocks();
  previous_.t = state_.t;
  previous_.x.resize(state_.x.size());
  previous_.v.resize(state_.v.size());
  runParallel(blocks.threads, [this, &blocks](int t) {
    const std::ptrdiff_t n = model_.numPoints(), lo = blocks.begin(t), hi = blocks.end(t);
    for (std::ptrdiff_t e = 0; e < 3; ++e) {
      std::copy(state_.x.data() + e * n + lo, state_.x.data() + e * n + hi,
                previous_.x.data() + e * n + lo);
      std::copy(state_.v.data() + e * n + lo, state_.v.data() + e * n + hi,
                previous_.v.data() + e * n + lo);
    }
  });
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
  std::optional<std::string> broken;
  if (result.ok) {
    std::array<StateScan, kMaxParallelThreads> parts;
    runParallel(blocks.threads, [this, &blocks, &parts](int t) {
      parts[static_cast<std::size_t>(t)] = scanPoints(state_, blocks.begin(t), blocks.end(t));
    });
    for (int t = 1; t < blocks.threads; ++t) parts[0].add(parts[static_cast<std::size_t>(t)]);
    broken = describeDivergence(parts[0], kDivergenceBound, speedBound);
    if (broken && model_.barrierContact()) {
      *broken +=
          " (barrier contact: forces are infinite inside a solid; an explicit step must "
          "not carry a point across the barrier's layer dhat: src/PHYSICS.md)";
    }
  } else {
    broken = result.message;
  }
  ++steps_;
  if (!broken) {
    // The work of the forces no potential describes, only for scenes that have them.
    addStepWork();
    if (steps_ - envelopeStart_ <= kEnergyEnvelopeSteps || steps_ % kEnergyCheckInterval == 0) {
      broken = energyGrowth();
    }
  }
  if (!broken) broken = obstacleDistance();
  if (!broken) return result;
  return diverged(*broken);
}

void Simulation::addStepWork() {
  if (model_.hasField()) {
    const double work = model_.fieldWork(previous_.x.data(), state_.x.data());
    fieldWork_ += work;
    workMoved_ += std::abs(work);
  }
  if (model_.hasUserForce()) {
    const double work = model_.userForceWork(previous_.x, state_.x);
    userWork_ += work;
    workMoved_ += std::abs(work);
  }
  if (model_.hasFriction()) frictionWork_ += model_.frictionWork(previous_, state_);
}

StepResult Simulation::diverged(const std::string& reason) {
  state_ = previous_;
  divergence_ = Divergence{state_.t, steps_, integrator_->kind(), reason};
  return StepResult::failure(divergence_->describe());
}

StepResult Simulation::checkEnergy() {
  if (divergence_) return StepResult::failure(divergence_->describe());
  // A state just checked by step() (or the start) needs nothing more.
  if (steps_ == 0 || steps_ - envelopeStart_ <= kEnergyEnvelopeSteps ||
      steps_ % kEnergyCheckInterval == 0) {
    return StepResult::success();
  }
  if (std::optional<std::string> broken = energyGrowth()) return diverged(*broken);
  return StepResult::success();
}

std::optional<std::string> Simulation::obstacleDistance() {
  if (!trackDistance_ && !model_.barrierContact()) return std::nullopt;
  const double d = model_.minObstacleDistance(state_.x.data());
  if (model_.barrierContact() && !(d > 0.0)) {
    std::ostringstream os;
    os << "a point reached a solid through the barrier (distance " << d << " m)";
    return os.str();
  }
  minDistance_ = std::min(minDistance_, d);
  return std::nullopt;
}

void Simulation::trackObstacleDistance() {
  trackDistance_ = true;
  minDistance_ = model_.minObstacleDistance(state_.x.data());
}

std::optional<double> Simulation::minObstacleDistance() const {
  if (!trackDistance_ || !std::isfinite(minDistance_)) return std::nullopt;
  return minDistance_;
}

void Simulation::setIntegrator(IntegratorKind kind) {
  if (kind != integrator_->kind()) integrator_ = makeIntegrator(kind, options_);
}

void Simulation::setIntegrator(IntegratorKind kind, const SolverOptions& options) {
  options_ = options;
  integrator_ = makeIntegrator(kind, options_);
}

void Simulation::stateEdited() {
  verified_ = false;
  JELLO_ASSERT(state_.x.size() == 3 * model_.numPoints() && state_.v.size() == state_.x.size(),
               "an edited state keeps its size");
  integrator_->restart();
  if (divergence_ && !findDivergence(state_)) divergence_.reset();
  energyEnvelope_ = std::max(0.0, model_.energy(state_).total() - externalWork());
  workMoved_ = 0.0;  // the envelope holds what the work's quadrature missed until now
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
