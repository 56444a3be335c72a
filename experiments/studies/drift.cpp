#include "experiments/studies/drift.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study_integrators.h"
#include "solvers/simulation.h"
#include "src/model.h"

namespace jello::experiments {

World driftScene(const DriftSetup& setup) {
  return spinningStiffCube(setup.k, 0.0);
}

std::vector<DriftRun> driftPlan(const World& scene, const DriftSetup& setup, bool quick) {
  const Model model(scene);
  const double wMax = maxAngularFrequency(model, initialState(scene));
  // Explicit steps at most explicitFraction of the limit, dividing the sample interval.
  const auto explicitStep = [&](IntegratorKind kind) {
    const double limit = setup.explicitFraction * predictedThreshold(kind, wMax, 0.0);
    return setup.interval / std::ceil(setup.interval / limit);
  };
  // Explicit methods never stable undamped (forward Euler) run at the smallest step of the
  // others, where they are seen to grow; the implicit ones at implicitDt. Not the adaptive
  // ones: a drift at a fixed step is what is measured.
  std::vector<IntegratorKind> kinds = quick ? quickDriftIntegrators() : fixedStepIntegrators();
  double smallest = setup.interval;
  for (IntegratorKind kind : kinds) {
    if (isExplicit(kind) && predictedThreshold(kind, wMax, 0.0) > 0.0) {
      smallest = std::min(smallest, explicitStep(kind));
    }
  }
  std::vector<std::pair<IntegratorKind, double>> runs;
  for (IntegratorKind kind : kinds) {
    if (!isExplicit(kind)) {
      runs.emplace_back(kind, setup.implicitDt);
    } else if (predictedThreshold(kind, wMax, 0.0) > 0.0) {
      runs.emplace_back(kind, explicitStep(kind));
    } else {
      runs.emplace_back(kind, smallest);
    }
  }
  std::vector<DriftRun> plan;
  for (const auto& [kind, dt] : runs) plan.push_back({kind, dt, dt * wMax});
  return plan;
}

CsvTable driftSeriesTable() {
  return CsvTable(
      {"integrator", "dt_s", "t_s", "energy_J", "energy_ratio", "angular_momentum_error"});
}

CsvTable driftSummaryTable() {
  return CsvTable({"integrator", "dt_s", "h_w_max", "steps", "wall_time_s", "energy_ratio_end",
                   "energy_deviation_max_first_half", "energy_deviation_max_second_half",
                   "angular_momentum_error_max", "outcome", "diverged_at_s"});
}

void runDrift(const World& scene, const DriftRun& run, const DriftSetup& setup, CsvTable& series,
              CsvTable& summary) {
  using Clock = std::chrono::steady_clock;
  Simulation sim(scene, run.kind, run.dt);
  const Model& model = sim.model();
  const double e0 = model.energy(sim.state()).total();
  const Vec3 l0 = model.angularMomentum(sim.state());
  const std::string name(integratorName(run.kind));
  // Every step divides the interval (driftPlan); samples at t = k * interval.
  const long perSample = std::max(1L, std::lround(setup.interval / run.dt));
  const long samples = std::lround(setup.time / setup.interval);
  double deviationEarly = 0.0, deviationLate = 0.0, angularError = 0.0, ratio = 1.0, seconds = 0.0;
  std::string outcome = "ok";
  double divergedAt = std::nan("");
  series.add({name, run.dt, 0.0, e0, 1.0, 0.0});
  for (long k = 1; k <= samples; ++k) {
    const auto t0 = Clock::now();
    for (long i = 0; i < perSample && outcome == "ok"; ++i) {
      if (!sim.step().ok) {
        // A divergence (the simulation's own check), or a solver that gave up.
        outcome = sim.divergence() ? "diverged" : "failed";
        divergedAt = sim.divergence() ? sim.divergence()->time : double(sim.steps()) * run.dt;
      }
    }
    seconds += std::chrono::duration<double>(Clock::now() - t0).count();
    if (outcome != "ok") break;
    const double t = double(k) * setup.interval;
    const double e = model.energy(sim.state()).total();
    const double l = norm(model.angularMomentum(sim.state()) - l0) / norm(l0);
    ratio = e / e0;
    double& deviation = 2 * k > samples ? deviationLate : deviationEarly;
    deviation = std::max(deviation, std::abs(ratio - 1.0));
    angularError = std::max(angularError, l);
    series.add({name, run.dt, t, e, ratio, l});
  }
  const double nan = std::nan("");
  const bool ok = outcome == "ok";
  summary.add({name, run.dt, run.hwMax, sim.steps(), seconds, ok ? ratio : nan,
               ok ? deviationEarly : nan, ok ? deviationLate : nan, ok ? angularError : nan,
               outcome, divergedAt});
}

}  // namespace jello::experiments
