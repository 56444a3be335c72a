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

#include "experiments/common/signal_handler.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/drift.h"
#include "experiments/studies/mode_theory.h"
#include "experiments/studies/parallel_for.h"
#include "experiments/studies/ranks.h"
#include "experiments/studies/run_context.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study_integrators.h"
#include "experiments/studies/trajectory_run.h"
#include "solvers/linalg/solver_threads.h"
#include "solvers/simulation.h"
#include "src/base/finite_options.h"
#include "src/base/out_of_memory.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"

namespace {

using namespace jello;
using namespace jello::experiments;
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

}  // namespace

int main(int argc, char** argv) {
  const Ranks ranks(argc, argv);
  if (!ranks.error().empty()) {
    std::cerr << "jello-work-precision: error: " << ranks.error() << '\n';
    return 1;
  }
  jello::exitCleanlyWhenOutOfMemory("jello-work-precision");
  jello::ignoreBrokenPipes("jello-work-precision");
  applySolverThreadSettings(argv);
  int levels = 5, repeats = 3, jobs = ranks.defaultJobs();
  double stiffK = 1e4, interval = 0.01;
  bool quick = false, quiet = false;
  std::string outDir = "experiments/results", name = "work_precision", worldsDir = JELLO_WORLDS_DIR;
  CLI::App app{
      "jello-work-precision: error over whole trajectories against wall time per integrator, "
      "and backward Euler's artificial damping"};
  app.add_option("--levels", levels, "Time steps per integrator (halving from its largest)")
      ->check(jello::cli::range(2, 12))
      ->capture_default_str();
  app.add_option("--repeats", repeats, "Timed runs per point (the CSV gives median, min, max)")
      ->check(jello::cli::range(1, 99))
      ->capture_default_str();
  app.add_option("--interval", interval, "Sampling interval of the errors, s")
      ->check(jello::cli::range(1e-4, 0.1))
      ->capture_default_str();
  app.add_option("--stiff-k", stiffK, "Stiffness of the stiff scene, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  DriftSetup drift;
  app.add_option("--drift-time", drift.time,
                 "Length of the long-run drift runs, s (default 100; --quick: 3)")
      ->check(jello::cli::range(0.1, 1e5));
  app.add_option("--drift-k", drift.k, "Stiffness of the drift runs' undamped cube, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--worlds", worldsDir, "Directory holding jello.w and sphere-drop.w")
      ->capture_default_str();
  app.add_option("--jobs", jobs, "Runs in parallel (per MPI rank)")
      ->check(jello::cli::range(1, 256))
      ->capture_default_str();
  app.add_option("--out-dir", outDir, "Directory for NAME.csv and NAME.json")
      ->capture_default_str();
  app.add_option("--name", name, "File name stem")->capture_default_str();
  app.add_flag("--quick", quick,
               "CI: jello.w over 0.04 s (before contact), 3 levels per method in its asymptotic "
               "range, 3 tolerances, one timed run");
  app.add_flag("--quiet", quiet, "No progress line");
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    // Under mpirun every rank parses the same line: rank 0 alone prints, all exit alike.
    return (ranks.root() ? app.exit(e) : e.get_exit_code()) == 0 ? 0 : 2;
  }
  // The tree as the run starts: the code that ran (outputs written later do not count).
  const nlohmann::json context = runContext(argc, argv);
  // The output directory is made and checked before the (long) run.
  if (!ranks.prepareOutput("jello-work-precision", outDir, name)) return 1;
  if (quick && app.count("--levels") == 0) levels = 3;
  if (quick && app.count("--repeats") == 0) repeats = 1;
  if (quick && app.count("--drift-time") == 0) drift.time = 3.0;
  const std::vector<double> rtols =
      quick ? std::vector<double>{1e-3, 1e-5, 1e-7}
            : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};

  std::vector<Scene> scenes;
  try {
    const std::filesystem::path dir(worldsDir);
    const World soft = readWorld(dir / "jello.w");
    // Name, description, world, window (s), h w_max of the reference.
    std::vector<std::tuple<std::string, std::string, World, double, double>> list;
    if (quick) {
      list.emplace_back("soft", "jello.w, 0.04 s (before its first contact)", soft, 0.04, 0.05);
    } else {
      // 0.25 s: the first contact with the floor and the plane and the rebound. Over longer
      // windows no reference converges: the contacts' damping switches on abruptly (no method
      // is better than first order through it) and differences grow after every contact. For
      // that first order, its reference takes 8x smaller steps.
      list.emplace_back("soft", "jello.w, 0.25 s (its first contact and rebound)", soft, 0.25,
                        0.00625);
      list.emplace_back("drop", "sphere-drop.w, 2 s (falls onto the sphere and the floor)",
                        readWorld(dir / "sphere-drop.w"), 2.0, 0.05);
      list.emplace_back("stiff", "free cube, k = 1e4, undamped, stretched 5% and spinning, 0.2 s",
                        spinningStiffCube(stiffK, 0.0), 0.2, 0.05);
    }
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
    // The references: RK4 at h w_max <= 0.05 or less (CVODE at rtol 1e-11 took minutes over
    // windows with contact), checked against RK4 at twice its step: fourth order makes that
    // check about 16x the reference's own error where the motion is smooth. One scene a thread.
    parallelFor(int(scenes.size()), jobs, "references", !quiet && ranks.root(), [&](int i) {
      Scene& s = scenes[static_cast<std::size_t>(i)];
      const double tiny =
          interval / std::pow(2.0, std::ceil(std::log2(interval * s.wMax / s.referenceHw)));
      Run ref = run(s.world, IntegratorKind::RK4, tiny, s.time, interval, {}, nullptr, true);
      if (!ref.failure.empty()) throw std::runtime_error(s.name + " reference: " + ref.failure);
      s.reference = std::move(ref.trajectory);
      s.reference.measure(Model(s.world));
      const Run check =
          run(s.world, IntegratorKind::RK4, 2 * tiny, s.time, interval, {}, &s.reference);
      if (!check.failure.empty()) throw std::runtime_error(s.name + " check: " + check.failure);
      s.referenceCheck = check.errors.positionMax;
      s.referenceStep = tiny;
    });
  } catch (const std::exception& e) {
    std::cerr << "jello-work-precision: error: " << e.what() << '\n';
    return 1;
  }

  std::vector<Task> tasks;
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
        for (int l = 0; l < levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
      } else {
        if (quick && kind != kQuickImplicit) continue;
        // From the sampling interval (quick: from h w_max <= 0.5, where order 1 shows).
        double dt = interval;
        if (quick) {
          while (dt * scene.wMax > 0.5) dt /= 2.0;
        }
        for (int l = 0; l < levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
      }
    }
  }
  // Artificial damping: the stiff cube without any damping (and without spin, so all its energy
  // is vibration) keeps its energy exactly; whatever a step loses is numerical. Measured over
  // 0.02 s (over longer spans backward Euler removes almost all at every step size) for
  // backward Euler, BDF2 and midpoint, beside the linear theory's prediction (mode_theory.h).
  const World undamped = spinningStiffCube(stiffK, 0.0, 0.0);
  const double dampingTime = 0.02;
  std::vector<std::pair<IntegratorKind, double>> dampingRuns;
  for (IntegratorKind kind : dampingRepresentatives()) {
    double dt = 0.01;
    for (int l = 0; l < (quick ? 2 : 8); ++l, dt /= 2.0) dampingRuns.emplace_back(kind, dt);
  }
  // Its start, measured once for every damping run.
  const Model undampedModel(undamped);
  const double undampedEnergy = undampedModel.energy(initialState(undamped)).total();
  ModalDecomposition undampedModes;
  double undampedWMax = 0.0;
  try {
    undampedModes = decomposeOnRestModes(undamped);
    undampedWMax = maxAngularFrequency(undampedModel, initialState(undamped));
  } catch (const std::exception& e) {
    std::cerr << "jello-work-precision: error: " << e.what() << '\n';
    return 1;
  }

  const World driftWorld = driftScene(drift);
  const std::vector<DriftRun> driftRuns = driftPlan(driftWorld, drift, quick);
  CsvTable driftSeries = driftSeriesTable(), driftSummary = driftSummaryTable();

  CsvTable table({"scene",
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
  CsvTable damping({"scene", "integrator", "dt_s", "h_w_max", "steps", "energy_start_J",
                    "energy_end_J", "energy_loss_J_per_s", "energy_decay_rate_per_s",
                    "energy_ratio", "predicted_energy_ratio", "predicted_decay_rate_per_s"});
  const std::size_t driftFirst = tasks.size() + dampingRuns.size();
  const int total = int(driftFirst + driftRuns.size());
  const auto started = Clock::now();
  const bool ok = ranks.run(
      "jello-work-precision", total, jobs, "runs", !quiet,
      [&](int i) {
        if (i >= int(driftFirst)) {
          const DriftRun& r = driftRuns[static_cast<std::size_t>(i) - driftFirst];
          runDrift(driftWorld, r, drift, driftSeries, driftSummary);
          return;
        }
        if (i >= int(tasks.size())) {
          const auto [kind, dt] = dampingRuns[static_cast<std::size_t>(i) - tasks.size()];
          const double e0 = undampedEnergy;
          const Run r = run(undamped, kind, dt, dampingTime, dt, {}, nullptr, true);
          if (!r.failure.empty()) throw std::runtime_error("damping run: " + r.failure);
          const double e1 = undampedModel.energy(r.trajectory.states.back()).total();
          const double predicted =
              predictedEnergy(undampedModes, kind, dt, r.count) / undampedModes.energy();
          damping.add({std::string("stiff_undamped"), std::string(integratorName(kind)), dt,
                       dt * undampedWMax, r.count, e0, e1, (e0 - e1) / dampingTime,
                       std::log(e0 / e1) / dampingTime, e1 / e0, predicted,
                       -std::log(predicted) / dampingTime});
          return;
        }
        const Task& t = tasks[static_cast<std::size_t>(i)];
        const Scene& s = scenes[t.scene];
        SolverOptions options;
        const bool cvode = isAdaptive(t.kind);
        if (cvode) {
          options.cvode.method = t.method;
          options.cvode.rtol = t.rtol;
          options.cvode.maxStepsPerCall = 100000000;
        }
        // The first run measures the errors and counts the work; every run is timed.
        const Run first = run(s.world, t.kind, t.dt, s.time, interval, options, &s.reference);
        std::vector<double> setup{first.setup}, firstStep{first.firstStep}, wall{first.steps};
        for (int rep = 1; rep < repeats && first.failure.empty(); ++rep) {
          const Run again = run(s.world, t.kind, t.dt, s.time, interval, options, nullptr);
          setup.push_back(again.setup);
          firstStep.push_back(again.firstStep);
          wall.push_back(again.steps);
        }
        const bool failed = !first.failure.empty();
        const double nan = std::nan("");
        const Errors& e = first.errors;
        const auto stat = [&](const char* n) {
          return findStatistic(first.statistics, n).value_or(nan);
        };
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
      },
      {&table, &damping, &driftSeries, &driftSummary});
  if (!ok) return 1;

  nlohmann::json sidecar = context;
  sidecar["program"] = "jello-work-precision";
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
  sidecar["parameters"] = {
      {"scenes", sceneInfo},
      {"levels", levels},
      {"repeats", repeats},
      {"sample_interval_s", interval},
      {"cvode_rtols", rtols},
      {"damping_scene",
       {{"k_N_per_m", stiffK},
        {"c_Ns_per_m", 0.0},
        {"time_s", dampingTime},
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
      {"jobs", jobs},
      {"quick", quick},
      {"position_error_max", "max over samples and points of |x - x_ref|"},
      {"position_error_rms", "RMS over samples of the max over points of |x - x_ref|"},
      {"energy_error_max", "max over samples of |E - E_ref| / E_ref(0)"},
      {"angular_momentum_error_max", "max over samples of |L - L_ref| / max |L_ref|"},
      {"wall_time", "the steps only (set-up apart), median of the repeats; first step inside"}};
  sidecar["wall_time_s"] = secondsSince(started);
  const std::filesystem::path dir = outDir;
  if (!ranks.writeOutput(
          "jello-work-precision", dir, name, table, sidecar,
          {{"damping", &damping}, {"drift", &driftSeries}, {"drift_summary", &driftSummary}})) {
    return 1;
  }
  if (!quiet && ranks.root()) {
    std::printf("wrote %zu + %zu + %zu rows to %s (%.1f s)\n", table.rows(), damping.rows(),
                driftSeries.rows(), dir.c_str(), sidecar["wall_time_s"].get<double>());
  }
  return 0;
}
