// jello-work-precision: error over whole trajectories against wall time for every integrator
// across time steps (cvode: BDF and Adams across tolerances) on three scenes with contact or
// stiffness in their windows (jello.w for 1 s, a 2 s drop onto the sphere, an undamped spinning
// stiff cube), against a converged reference sampled every interval; timings are medians of
// repeated runs with set-up apart, and the solvers' work is counted. Also backward Euler's
// artificial damping on the undamped stiff cube, and every integrator's long-run drift of
// energy and angular momentum on an undamped free cube (drift.h).
//   jello-work-precision [--quick] [--levels N] [--repeats N] [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "experiments/studies/csv_table.h"
#include "experiments/studies/drift.h"
#include "experiments/studies/mode_theory.h"
#include "experiments/studies/parallel_for.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study.h"
#include "experiments/studies/study_integrators.h"
#include "experiments/studies/trajectory_run.h"
#include "solvers/simulation.h"
#include "src/base/finite_options.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"

namespace {

using namespace jello;
using namespace jello::experiments;

struct Options {
  int levels = 5, repeats = 3;
  double stiffK = 1e4, interval = 0.01;
  DriftSetup drift;
  std::string worldsDir = JELLO_WORLDS_DIR;
};

struct Scene {
  std::string name, description;
  World world;
  double time;          // s, the window
  double dampingRatio;  // s, c/k, for the explicit methods' predicted limits
  double wMax;          // rad/s at the start
  Trajectory reference;
  double referenceCheck = 0.0;  // m, max over the samples of |reference - rk4 at twice its step|
  double referenceStep = 0.0;   // s
  double referenceHw = 0.05;    // h w_max of the reference's RK4 steps
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// A task of the grid: one configuration, run `repeats` times.
struct Task {
  std::size_t scene;
  IntegratorKind kind;
  double dt = 0.0;  // s (cvode: the sample interval)
  CvodeMethod method = CvodeMethod::Bdf;
  double rtol = 0.0;  // cvode only
};

// Artificial damping: the stiff cube without any damping (and without spin, so all its energy
// is vibration) keeps its energy exactly; whatever a step loses is numerical. Measured over
// 0.02 s (over longer spans backward Euler removes almost all at every step size) for backward
// Euler, BDF2 and midpoint (one of each A-stable linear model), beside the linear theory's
// prediction (mode_theory.h). Its start is measured once for every run.
struct DampingStudy {
  explicit DampingStudy(const Options& opt, bool quick)
      : world(spinningStiffCube(opt.stiffK, 0.0, 0.0)),
        model(world),
        energy(model.energy(initialState(world)).total()),
        modes(decomposeOnRestModes(world)),
        wMax(maxAngularFrequency(model, initialState(world))) {
    for (IntegratorKind kind : dampingRepresentatives()) {
      double dt = 0.01;
      for (int l = 0; l < (quick ? 2 : 8); ++l, dt /= 2.0) runs.emplace_back(kind, dt);
    }
  }
  static constexpr double kTime = 0.02;  // s
  World world;
  Model model;
  double energy;  // J, at the start
  ModalDecomposition modes;
  double wMax;
  std::vector<std::pair<IntegratorKind, double>> runs;
};

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("--levels", opt.levels, "Time steps per integrator (halving from its largest)")
      ->check(jello::cli::range(2, 12))
      ->capture_default_str();
  app.add_option("--repeats", opt.repeats, "Timed runs per point (the CSV gives median, min, max)")
      ->check(jello::cli::range(1, 99))
      ->capture_default_str();
  app.add_option("--interval", opt.interval, "Sampling interval of the errors, s")
      ->check(jello::cli::range(1e-4, 0.1))
      ->capture_default_str();
  app.add_option("--stiff-k", opt.stiffK, "Stiffness of the stiff scene, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--drift-time", opt.drift.time,
                 "Length of the long-run drift runs, s (default 100; --quick: 3)")
      ->check(jello::cli::range(0.1, 1e5));
  app.add_option("--drift-k", opt.drift.k, "Stiffness of the drift runs' undamped cube, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--worlds", opt.worldsDir, "Directory holding jello.w and sphere-drop.w")
      ->capture_default_str();
}

// The scenes with their w_max, and each one's reference: RK4 at h w_max <= 0.05 or less
// (CVODE at rtol 1e-11 took minutes over windows with contact), checked against RK4 at twice
// its step: fourth order makes that check about 16x the reference's own error where the motion
// is smooth. One scene a thread.
std::vector<Scene> scenesWithReferences(const Options& opt, const Study& study) {
  const std::filesystem::path dir(opt.worldsDir);
  const World soft = readWorld(dir / "jello.w");
  // Name, description, world, window (s), h w_max of the reference.
  std::vector<std::tuple<std::string, std::string, World, double, double>> list;
  if (study.quick) {
    list.emplace_back("soft", "jello.w, 0.04 s (before its first contact)", soft, 0.04, 0.05);
  } else {
    // 0.25 s: the first contact with the floor and the plane and the rebound. Over longer
    // windows no reference converges: the contacts' damping switches on abruptly (no method is
    // better than first order through it) and differences grow after every contact. For that
    // first order, its reference takes 8x smaller steps.
    list.emplace_back("soft", "jello.w, 0.25 s (its first contact and rebound)", soft, 0.25,
                      0.00625);
    list.emplace_back("drop", "sphere-drop.w, 2 s (falls onto the sphere and the floor)",
                      readWorld(dir / "sphere-drop.w"), 2.0, 0.05);
    list.emplace_back("stiff", "free cube, k = 1e4, undamped, stretched 5% and spinning, 0.2 s",
                      spinningStiffCube(opt.stiffK, 0.0), 0.2, 0.05);
  }
  std::vector<Scene> scenes;
  for (auto& [label, description, w, time, hw] : list) {
    const Model model(w);
    scenes.push_back({label,
                      description,
                      w,
                      time,
                      w.kElastic > 0 ? w.dElastic / w.kElastic : 0.0,
                      maxAngularFrequency(model, initialState(w)),
                      {},
                      0.0,
                      0.0,
                      hw});
  }
  const double interval = opt.interval;
  parallelFor(
      int(scenes.size()), study.jobs, "references", !study.quiet && study.ranks().root(),
      [&](int i) {
        Scene& s = scenes[static_cast<std::size_t>(i)];
        const double tiny =
            interval / std::pow(2.0, std::ceil(std::log2(interval * s.wMax / s.referenceHw)));
        Run ref = run(s.world, IntegratorKind::RK4, tiny, s.time, interval, {}, nullptr, true);
        if (!ref.failure.empty()) {
          throw std::runtime_error(s.name + " reference: " + ref.failure);
        }
        s.reference = std::move(ref.trajectory);
        s.reference.measure(Model(s.world));
        const Run check =
            run(s.world, IntegratorKind::RK4, 2 * tiny, s.time, interval, {}, &s.reference);
        if (!check.failure.empty()) {
          throw std::runtime_error(s.name + " check: " + check.failure);
        }
        s.referenceCheck = check.errors.positionMax;
        s.referenceStep = tiny;
      });
  return scenes;
}

// The steps (and tolerances) each integrator runs on each scene.
std::vector<Task> tasksOf(const std::vector<Scene>& scenes, const Options& opt,
                          const std::vector<double>& rtols, bool quick) {
  std::vector<Task> tasks;
  const double interval = opt.interval;
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const Scene& scene = scenes[s];
    for (IntegratorKind kind : studyOrder()) {
      if (isAdaptive(kind)) {
        for (CvodeMethod method : {CvodeMethod::Bdf, CvodeMethod::Adams}) {
          if (quick && method == CvodeMethod::Adams) continue;
          for (double rtol : rtols) tasks.push_back({s, kind, interval, method, rtol});
        }
      } else if (isExplicit(kind)) {
        // The largest step: the largest interval / 2^j below 0.9 of the predicted limit.
        // --quick starts the first-order methods where h w_max <= 0.5, in the asymptotic range
        // where their order shows, and keeps the runs short.
        double limit = 0.9 * predictedThreshold(kind, scene.wMax, scene.dampingRatio);
        if (limit <= 0.0) continue;  // forward Euler on an undamped scene: never stable
        if (quick && linearModel(kind) != LinearModel::RungeKutta4) {
          limit = std::min(limit, 0.5 / scene.wMax);
        }
        double dt = interval;
        while (dt > limit) dt /= 2.0;
        for (int l = 0; l < opt.levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
      } else {
        if (quick && kind != kQuickImplicit) continue;
        // From the sampling interval (quick: from h w_max <= 0.5, where order 1 shows).
        double dt = interval;
        if (quick) {
          while (dt * scene.wMax > 0.5) dt /= 2.0;
        }
        for (int l = 0; l < opt.levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
      }
    }
  }
  return tasks;
}

CsvTable precisionTable() {
  return CsvTable({"scene",
                   "integrator",
                   "cvode_method",
                   "dt_s",
                   "rtol",
                   "steps",
                   "repeats",
                   "setup_s",
                   "first_step_s",
                   "wall_time_s",
                   "wall_time_min_s",
                   "wall_time_max_s",
                   "position_error_max_m",
                   "position_error_rms_m",
                   "energy_error_max",
                   "angular_momentum_error_max",
                   "force_evaluations",
                   "factorizations",
                   "newton_iterations",
                   "projective_iterations",
                   "cvode_steps",
                   "outcome"});
}

CsvTable dampingTable() {
  return CsvTable({"scene", "integrator", "dt_s", "h_w_max", "steps", "energy_start_J",
                   "energy_end_J", "energy_loss_J_per_s", "energy_decay_rate_per_s", "energy_ratio",
                   "predicted_energy_ratio", "predicted_decay_rate_per_s"});
}

// One task: the first run measures the errors and counts the work; every run is timed.
void runTask(const Task& t, const Scene& s, const Options& opt, CsvTable& table) {
  SolverOptions options;
  const bool cvode = isAdaptive(t.kind);
  if (cvode) {
    options.cvode.method = t.method;
    options.cvode.rtol = t.rtol;
    options.cvode.maxStepsPerCall = 100000000;
  }
  const Run first = run(s.world, t.kind, t.dt, s.time, opt.interval, options, &s.reference);
  std::vector<double> setup{first.setup}, firstStep{first.firstStep}, wall{first.steps};
  for (int rep = 1; rep < opt.repeats && first.failure.empty(); ++rep) {
    const Run again = run(s.world, t.kind, t.dt, s.time, opt.interval, options, nullptr);
    setup.push_back(again.setup);
    firstStep.push_back(again.firstStep);
    wall.push_back(again.steps);
  }
  const bool failed = !first.failure.empty();
  const double nan = std::nan("");
  const Errors& e = first.errors;
  const auto stat = [&](const char* n) { return findStatistic(first.statistics, n).value_or(nan); };
  table.add({s.name,
             std::string(integratorName(t.kind)),
             std::string(cvode ? (t.method == CvodeMethod::Bdf ? "bdf" : "adams") : "none"),
             t.dt,
             cvode ? t.rtol : nan,
             first.count,
             long(wall.size()),
             median(setup),
             median(firstStep),
             median(wall),
             *std::min_element(wall.begin(), wall.end()),
             *std::max_element(wall.begin(), wall.end()),
             failed ? nan : e.positionMax,
             failed ? nan : e.positionRms,
             failed ? nan : e.energyMax,
             failed ? nan : e.angularMomentumMax,
             first.forceEvaluations,
             stat("factorizations"),
             stat("newton_iterations"),
             stat("projective_iterations"),
             stat("cvode_steps"),
             std::string(failed ? "failed" : "ok")});
}

void runDamping(const DampingStudy& d, IntegratorKind kind, double dt, CsvTable& damping) {
  const double e0 = d.energy, time = DampingStudy::kTime;
  const Run r = run(d.world, kind, dt, time, dt, {}, nullptr, true);
  if (!r.failure.empty()) throw std::runtime_error("damping run: " + r.failure);
  const double e1 = d.model.energy(r.trajectory.states.back()).total();
  const double predicted = predictedEnergy(d.modes, kind, dt, r.count) / d.modes.energy();
  damping.add({std::string("stiff_undamped"), std::string(integratorName(kind)), dt, dt * d.wMax,
               r.count, e0, e1, (e0 - e1) / time, std::log(e0 / e1) / time, e1 / e0, predicted,
               -std::log(predicted) / time});
}

nlohmann::json parameters(const Options& opt, const Study& study, const std::vector<Scene>& scenes,
                          const std::vector<double>& rtols) {
  nlohmann::json sceneInfo = nlohmann::json::array();
  for (const Scene& s : scenes) {
    sceneInfo.push_back({{"scene", s.name},
                         {"description", s.description},
                         {"time_s", s.time},
                         {"k_N_per_m", s.world.kElastic},
                         {"c_Ns_per_m", s.world.dElastic},
                         {"w_max_rad_per_s", s.wMax},
                         {"reference", "rk4"},
                         {"reference_dt_s", s.referenceStep},
                         {"reference_h_w_max", s.referenceHw},
                         {"reference_vs_twice_its_step_m", s.referenceCheck}});
  }
  const DriftSetup& drift = opt.drift;
  return {
      {"scenes", sceneInfo},
      {"levels", opt.levels},
      {"repeats", opt.repeats},
      {"sample_interval_s", opt.interval},
      {"cvode_rtols", rtols},
      {"damping_scene",
       {{"k_N_per_m", opt.stiffK},
        {"c_Ns_per_m", 0.0},
        {"time_s", DampingStudy::kTime},
        {"pose", "stretched 5% along x, at rest"},
        {"prediction", "linear theory on the modes at rest (experiments/studies/mode_theory.h)"}}},
      {"drift_scene",
       {{"k_N_per_m", drift.k},
        {"c_Ns_per_m", 0.0},
        {"time_s", drift.time},
        {"sample_interval_s", drift.interval},
        {"implicit_dt_s", drift.implicitDt},
        {"explicit_fraction_of_limit", drift.explicitFraction},
        {"pose", "stretched 5% along x, spinning at 2 rad/s about z, touching nothing"}}},
      {"jobs", study.jobs},
      {"quick", study.quick},
      {"position_error_max", "max over samples and points of |x - x_ref|"},
      {"position_error_rms", "RMS over samples of the max over points of |x - x_ref|"},
      {"energy_error_max", "max over samples of |E - E_ref| / E_ref(0)"},
      {"angular_momentum_error_max", "max over samples of |L - L_ref| / max |L_ref|"},
      {"wall_time", "the steps only (set-up apart), median of the repeats; first step inside"}};
}

}  // namespace

int main(int argc, char** argv) {
  Study study("jello-work-precision",
              "error over whole trajectories against wall time per integrator, and backward "
              "Euler's artificial damping",
              "work_precision", argc, argv);
  Options opt;
  addOptions(study.app(), opt);
  study.addCommonOptions(
      "CI: jello.w over 0.04 s (before contact), 3 levels per method in its asymptotic range, 3 "
      "tolerances, one timed run",
      "Runs in parallel (per MPI rank)");
  if (const auto code = study.start(argc, argv)) return *code;
  if (study.quick && !study.given("--levels")) opt.levels = 3;
  if (study.quick && !study.given("--repeats")) opt.repeats = 1;
  if (study.quick && !study.given("--drift-time")) opt.drift.time = 3.0;
  const std::vector<double> rtols =
      study.quick ? std::vector<double>{1e-3, 1e-5, 1e-7}
                  : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};

  // The drift runs are planned first: a --drift-k they cannot use fails the run at once, not
  // after the references.
  const World driftWorld = driftScene(opt.drift);
  std::vector<DriftRun> driftRuns;
  try {
    driftRuns = driftPlan(driftWorld, opt.drift, study.quick);
  } catch (const std::exception& e) {
    // Spectra's eigensolver throws on a lattice it cannot resolve (--drift-k 1e308 or 1e-300).
    std::ostringstream what;
    what << "the drift runs (--drift-k " << opt.drift.k << ") could not be planned: " << e.what();
    return study.fail(what.str());
  }
  std::vector<Scene> scenes;
  std::optional<DampingStudy> damped;
  try {
    scenes = scenesWithReferences(opt, study);
    damped.emplace(opt, study.quick);
  } catch (const std::exception& e) {
    return study.fail(e.what());
  }
  const std::vector<Task> tasks = tasksOf(scenes, opt, rtols, study.quick);

  CsvTable table = precisionTable(), damping = dampingTable();
  CsvTable driftSeries = driftSeriesTable(), driftSummary = driftSummaryTable();
  const std::size_t dampingFirst = tasks.size(), driftFirst = dampingFirst + damped->runs.size();
  const bool ok = study.run(int(driftFirst + driftRuns.size()), "runs",
                            [&](int index) {
                              const auto i = static_cast<std::size_t>(index);
                              if (i >= driftFirst) {
                                runDrift(driftWorld, driftRuns[i - driftFirst], opt.drift,
                                         driftSeries, driftSummary);
                              } else if (i >= dampingFirst) {
                                const auto [kind, dt] = damped->runs[i - dampingFirst];
                                runDamping(*damped, kind, dt, damping);
                              } else {
                                runTask(tasks[i], scenes[tasks[i].scene], opt, table);
                              }
                            },
                            {&table, &damping, &driftSeries, &driftSummary});
  if (!ok) return 1;
  return study.finish(
      table, parameters(opt, study, scenes, rtols),
      {{"damping", &damping}, {"drift", &driftSeries}, {"drift_summary", &driftSummary}});
}
