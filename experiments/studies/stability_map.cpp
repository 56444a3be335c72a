// jello-stability: for each integrator and stiffness k, the largest stable time step, measured
// by bisection on two standard scenes and predicted from the scene's own w_max and each
// method's stability region (stability_analysis.h). Long-format CSV plus a JSON sidecar.
//   jello-stability [--quick] [--k LIST] [--scenes free,wall] [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <variant>
#include <vector>

#include "experiments/studies/csv_table.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study.h"
#include "experiments/studies/study_integrators.h"
#include "solvers/simulation.h"
#include "src/base/finite_options.h"

namespace {

using namespace jello;
using namespace jello::experiments;

struct Options {
  std::vector<double> ks;
  std::vector<std::string> scenes{"free", "wall"};
  std::vector<std::string> integrators;
  double dampingRatio = 1e-5;  // s, c/k
  double contactRatio = 20.0;  // kCollision / k in the wall scene
  BlowUpRule rule;
  double tolerance = 0.02;
  double dtMax = 0.05;  // s
  double rtol = 1e-3;   // cvode
};

struct Point {
  std::string scene;
  double k;
  World world;
  double wMax;
};

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("--k", opt.ks, "Spring stiffnesses, N/m (default 10 to 1e6, 2 per decade)")
      ->check(jello::cli::positive())
      ->delimiter(',');
  app.add_option("--scenes", opt.scenes, "Scenes: free (no contact), wall (resting on the floor)")
      ->check(CLI::IsMember({"free", "wall"}))
      ->delimiter(',');
  app.add_option("--integrators", opt.integrators,
                 "Integrators (default all): " + namedIntegratorsHelp())
      ->delimiter(',');
  app.add_option("--damping-ratio", opt.dampingRatio, "Spring damping c/k, s")
      ->check(jello::cli::nonNegative())
      ->capture_default_str();
  app.add_option("--contact-ratio", opt.contactRatio, "Wall scene: contact stiffness over k")
      ->check(jello::cli::positive())
      ->capture_default_str();
  // Bounded so that every run's step count fits (time / dt with dt down to 1e-9 s; 1e308
  // overflowed it and only --min-steps ran, reported as thresholds).
  app.add_option("--time", opt.rule.time, "Simulated time a stable run must survive, s")
      ->check(jello::cli::range(BlowUpRule::kMinTime, BlowUpRule::kMaxTime))
      ->capture_default_str();
  app.add_option("--min-steps", opt.rule.minSteps,
                 "Explicit methods run at least this many steps (slow growth shows)")
      ->check(CLI::Range(1L, 100000000L))
      ->capture_default_str();
  app.add_option("--energy-factor", opt.rule.energyFactor,
                 "Blow-up when the total energy exceeds this times its envelope: the largest "
                 "energy of the first 64 steps for explicit methods, the start's for implicit ones")
      ->check(jello::cli::range(1.0, 1e12))
      ->capture_default_str();
  app.add_option("--tolerance", opt.tolerance, "Bisection stops at unstable/stable <= 1 + this")
      ->check(jello::cli::range(1e-4, 1.0))
      ->capture_default_str();
  // Not subnormal (4.9e-324 was reported stable to that step).
  app.add_option("--dt-max", opt.dtMax, "Largest time step tried, s")
      ->check(jello::cli::range(BlowUpRule::kMinDtMax, BlowUpRule::kMaxDtMax))
      ->capture_default_str();
  app.add_option("--rtol", opt.rtol, "cvode's relative tolerance")
      ->check(jello::cli::positive())
      ->capture_default_str();
}

// --quick's defaults where the options did not say, and the full grid's stiffnesses.
void applyDefaults(const Study& study, Options& opt) {
  if (study.quick) {
    if (!study.given("--k")) opt.ks = {1e2, 1e4};
    if (!study.given("--scenes")) opt.scenes = {"free"};
    if (!study.given("--time")) opt.rule.time = 0.1;
    if (!study.given("--min-steps")) opt.rule.minSteps = 500;
    if (!study.given("--tolerance")) opt.tolerance = 0.05;
  }
  if (opt.ks.empty()) {
    for (int i = 2; i <= 12; ++i) opt.ks.push_back(std::pow(10.0, i / 2.0));
  }
}

// The scenes and their w_max (serial: a Lanczos solve each, milliseconds).
std::vector<Point> grid(const Options& opt) {
  std::vector<Point> points;
  for (const std::string& scene : opt.scenes) {
    for (double k : opt.ks) {
      World w = stabilityScene(scene, k, opt.dampingRatio, opt.contactRatio);
      const Model model(w);
      const double wMax = maxAngularFrequency(model, initialState(w));
      points.push_back({scene, k, std::move(w), wMax});
    }
  }
  return points;
}

// One grid point: the predicted threshold and the measured one, a row each.
void measure(const Options& opt, const Point& p, IntegratorKind kind, const SolverOptions& solver,
             CsvTable& table) {
  const std::string name(integratorName(kind));
  const double c = opt.dampingRatio * p.k, zeta = opt.dampingRatio * p.wMax / 2.0;
  const double predicted = predictedThreshold(kind, p.wMax, opt.dampingRatio);
  table.add({p.scene, name, p.k, c, p.wMax, zeta, std::string("predicted"), predicted,
             predicted * p.wMax,
             std::string(std::isinf(predicted) ? "unconditional"
                         : predicted > 0.0     ? "limit"
                                               : "never"),
             0L, 0.0});
  // The search starts at Courant number 1 for every method, not at its prediction, so the
  // measurement does not lean on what it is compared with.
  const double guess = 1.0 / p.wMax;
  const auto t0 = std::chrono::steady_clock::now();
  const Threshold t =
      findThreshold(p.world, kind, opt.rule, guess, opt.dtMax, opt.tolerance, 1e-8, solver);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string outcome = t.stableToMax()  ? "stable_to_max"
                              : t.stable > 0.0 ? "threshold"
                                               : "unstable_to_min";
  table.add({p.scene, name, p.k, c, p.wMax, zeta, std::string("measured"), t.stable,
             t.stable * p.wMax, outcome, long(t.trials), wall});
}

nlohmann::json parameters(const Options& opt, const Study& study) {
  return {{"k_N_per_m", opt.ks},
          {"scenes", opt.scenes},
          {"damping_ratio_s", opt.dampingRatio},
          {"wall_contact_ratio", opt.contactRatio},
          {"blow_up",
           {{"time_s", opt.rule.time},
            {"explicit_min_steps", opt.rule.minSteps},
            {"energy_factor", opt.rule.energyFactor},
            {"energy_envelope_steps", kBlowUpEnvelopeSteps},
            {"divergence_bound_m", kDivergenceBound}}},
          {"bisection_tolerance", opt.tolerance},
          {"dt_max_s", opt.dtMax},
          {"cvode_rtol", opt.rtol},
          {"jobs", study.jobs},
          {"quick", study.quick}};
}

}  // namespace

int main(int argc, char** argv) {
  Study study("jello-stability",
              "largest stable time step per integrator and stiffness, measured against predicted",
              "stability", argc, argv);
  Options opt;
  addOptions(study.app(), opt);
  study.addCommonOptions("Small grid for CI: k = 100 and 10^4, free scene, 0.1 s, 5% bisection");
  std::vector<IntegratorKind> kinds;
  const auto checked = study.start(argc, argv, [&]() -> std::string {
    auto named =
        namedIntegrators(opt.integrators, {allIntegrators().begin(), allIntegrators().end()});
    if (const std::string* unknown = std::get_if<std::string>(&named)) {
      return "unknown integrator '" + *unknown + "' (known: " + namedIntegratorsHelp() + ")";
    }
    kinds = std::get<std::vector<IntegratorKind>>(std::move(named));
    return "";
  });
  if (checked) return *checked;
  applyDefaults(study, opt);

  std::vector<Point> points;
  try {
    points = grid(opt);
  } catch (const std::exception& e) {
    return study.fail(e.what());
  }
  CsvTable table({"scene", "integrator", "k_N_per_m", "c_Ns_per_m", "w_max_rad_per_s", "zeta_max",
                  "source", "dt_s", "courant_number", "outcome", "trials", "wall_time_s"});
  SolverOptions solver;
  solver.cvode.rtol = opt.rtol;
  const int tasks = int(points.size() * kinds.size());
  const bool ok =
      study.run(tasks, "grid points",
                [&](int i) {
                  const Point& p = points[static_cast<std::size_t>(i) / kinds.size()];
                  measure(opt, p, kinds[static_cast<std::size_t>(i) % kinds.size()], solver, table);
                },
                {&table});
  if (!ok) return 1;
  return study.finish(table, parameters(opt, study));
}
