#include "experiments/studies/trajectory_run.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "solvers/simulation.h"

namespace jello::experiments {

void Trajectory::measure(const Model& model) {
  energy.clear();
  angularMomentum.clear();
  for (const State& s : states) {
    energy.push_back(model.energy(s).total());
    angularMomentum.push_back(model.angularMomentum(s));
  }
}

ErrorMeter::ErrorMeter(const Model& model, const Trajectory& reference)
    : model_(model), reference_(reference) {
  energyScale_ = std::abs(reference.energy.front());
  for (const Vec3& l : reference.angularMomentum) angularScale_ = std::max(angularScale_, norm(l));
}

void ErrorMeter::sample(std::size_t k, const State& s) {
  const State& r = reference_.states.at(k);
  double worst = 0.0;
  for (int p = 0; p < s.numPoints(); ++p) {
    worst = std::max(worst, norm(s.position(p) - r.position(p)));
  }
  e_.positionMax = std::max(e_.positionMax, worst);
  squares_ += worst * worst;
  ++samples_;
  e_.energyMax = std::max(
      e_.energyMax, std::abs(model_.energy(s).total() - reference_.energy.at(k)) / energyScale_);
  // A scene without rotation (max |L_ref| near zero) has no relative angular momentum error.
  e_.angularMomentumMax =
      angularScale_ > 1e-9
          ? std::max(
                e_.angularMomentumMax,
                norm(model_.angularMomentum(s) - reference_.angularMomentum.at(k)) / angularScale_)
          : std::nan("");
}

Errors ErrorMeter::result() const {
  Errors e = e_;
  e.positionRms = samples_ ? std::sqrt(squares_ / double(samples_)) : 0.0;
  return e;
}

Run run(const World& w, IntegratorKind kind, double dt, double time, double interval,
        const SolverOptions& options, const Trajectory* reference, bool keep) {
  Run r;
  const auto t0 = Clock::now();
  Simulation sim(w, kind, dt, options);
  r.setup = secondsSince(t0);
  const long perSample = std::lround(interval / dt), samples = std::lround(time / interval);
  std::optional<ErrorMeter> meter;
  if (reference) meter.emplace(sim.model(), *reference);
  if (keep) r.trajectory = {interval, {sim.state()}, {}, {}};
  const long forcesBefore = sim.model().counts().springs;
  for (long k = 1; k <= samples && r.failure.empty(); ++k) {
    for (long i = 0; i < perSample; ++i) {
      const auto s0 = Clock::now();
      const StepResult result = sim.step();
      const double seconds = secondsSince(s0);
      (r.count == 0 ? r.firstStep : r.steps) += seconds;
      ++r.count;
      if (!result.ok) {
        r.failure = result.message;
        break;
      }
    }
    if (!r.failure.empty()) break;
    if (meter) meter->sample(std::size_t(k), sim.state());
    if (keep) r.trajectory.states.push_back(sim.state());
  }
  r.steps += r.firstStep;
  r.forceEvaluations = sim.model().counts().springs - forcesBefore;
  r.statistics = sim.integrator().statistics();
  if (meter) r.errors = meter->result();
  return r;
}

}  // namespace jello::experiments
