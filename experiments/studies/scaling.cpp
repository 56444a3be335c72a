// jello-scaling: wall time per simulated second against cube resolution N, for every
// integrator at a fixed stiffness; for implicit and cvode with CHOLMOD and with CG, the
// factorization and the solves split out. The scene is the stiff cube of work-precision
// (k = 10^4 by default, stretched 5% and spinning) resampled to N^3 points: the mass per point
// and the stiffness per spring stay, so w_max, and the explicit methods' stable step, stay too.
// Also the crossover atlas (atlas.h): over k and N, each integrator's cost at the largest step
// that keeps the visible motion within a tolerance.
//   jello-scaling [--quick] [--n LIST] [--budget S] [--atlas-k LIST] [--atlas-n LIST]
//                 [--atlas-scene falling|free] [--atlas-references DIR]
//                 [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "experiments/common/signal_handler.h"
#include "experiments/studies/atlas.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/ranks.h"
#include "experiments/studies/run_context.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study_integrators.h"
#include "solvers/linalg/solver_threads.h"
#include "solvers/simulation.h"
#include "src/base/finite_options.h"
#include "src/base/out_of_memory.h"
#include "src/world/scene_builder.h"

namespace {

using namespace jello;
using namespace jello::experiments;
using Clock = std::chrono::steady_clock;

struct Task {
  int n;
  IntegratorKind kind;
  LinearSolverKind solver = LinearSolverKind::Cholmod;  // implicit, cvode
};

}  // namespace

int main(int argc, char** argv) {
  const Ranks ranks(argc, argv);
  if (!ranks.error().empty()) {
    std::cerr << "jello-scaling: error: " << ranks.error() << '\n';
    return 1;
  }
  jello::exitCleanlyWhenOutOfMemory("jello-scaling");
  jello::ignoreBrokenPipes("jello-scaling");
  applySolverThreadSettings(argv);
  std::vector<int> ns{8, 12, 16, 24, 32};
  double k = 1e4, budget = 3.0, implicitDt = 0.01, rtol = 1e-3;
  int jobs = ranks.defaultJobs();
  int cvodeDirectMaxN = 16;
  bool quick = false, quiet = false;
  std::string outDir = "experiments/results", name = "scaling";
  CLI::App app{"jello-scaling: wall time per simulated second against cube resolution"};
  app.add_option("--n", ns, "Cube resolutions")->check(jello::cli::range(2, 64))->delimiter(',');
  app.add_option("--k", k, "Spring stiffness, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--budget", budget, "Wall seconds to run each point for (at least one step)")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--implicit-dt", implicitDt, "Time step of implicit, output interval of cvode, s")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--rtol", rtol, "cvode's relative tolerance")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--jobs", jobs,
                 "Points run in parallel (1 gives timings free of a neighbour's memory traffic)")
      ->check(jello::cli::range(1, 256))
      ->capture_default_str();
  app.add_option("--out-dir", outDir, "Directory for NAME.csv and NAME.json")
      ->capture_default_str();
  app.add_option("--name", name, "File name stem")->capture_default_str();
  app.add_option("--cvode-cholmod-max-n", cvodeDirectMaxN,
                 "Largest N for cvode with CHOLMOD (one output interval there needs several "
                 "factorizations of minutes each at N = 32)")
      ->capture_default_str();
  // The whole atlas is hours of CPU at N = 32 (scripts/run-experiments.sh runs N = 8; a cluster
  // runs the rest under mpirun).
  std::vector<double> atlasK{1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8};
  std::vector<int> atlasN{8, 16, 32};
  AtlasSetup atlas;
  app.add_option("--atlas-k", atlasK,
                 "The atlas's stiffnesses, N/m (default 1e2 to 1e8 by decades; --no-atlas: none)")
      ->check(jello::cli::positive())
      ->delimiter(',');
  app.add_option("--atlas-n", atlasN, "The atlas's cube resolutions (default 8, 16, 32)")
      ->check(jello::cli::range(2, 64))
      ->delimiter(',');
  app.add_option("--atlas-tolerance", atlas.tolerance,
                 "The atlas's accuracy on the visible motion, m at the corners")
      ->check(jello::cli::positive())
      ->capture_default_str();
  std::string atlasSceneName = "falling";
  app.add_option("--atlas-scene", atlasSceneName,
                 "The atlas's scene: falling (thrown, spinning, onto the floor under gravity) or "
                 "free (the same throw and spin without gravity: no contact)")
      ->check(CLI::IsMember({"falling", "free"}))
      ->capture_default_str();
  app.add_option("--atlas-budget", atlas.runBudget,
                 "Wall seconds of one atlas run beyond which smaller steps are not tried")
      ->check(jello::cli::positive())
      ->capture_default_str();
  std::string referenceDir;
  app.add_option("--atlas-references", referenceDir,
                 "Directory the atlas's RK4 references are read from, or written to once computed "
                 "(with their last state every --atlas-checkpoint s meanwhile: a stopped run "
                 "resumes there)");
  app.add_option("--atlas-checkpoint", atlas.checkpoint,
                 "Wall seconds between the saved states of a reference being computed")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--atlas-reference-threads", atlas.referenceThreads,
                 "Threads of the model while a reference is computed, with --jobs 1 (default: the "
                 "runs' own, JELLO_THREADS or the CPUs)")
      ->check(jello::cli::range(1, 64));
  app.add_flag_function(
      "--no-atlas", [&](std::int64_t) { atlasK.clear(); }, "Leave the atlas out");
  bool noGrid = false;
  app.add_flag("--no-grid", noGrid,
               "Leave the resolution grid out: the atlas alone (NAME.csv holds only its header)");
  app.add_flag("--quick", quick,
               "CI: N = 6 and 8, 0.3 s per point; the atlas at k = 1e3 and 1e5, N = 8, with "
               "symplectic, rk4, implicit, midpoint and projective, 4 steps tried each");
  app.add_flag("--quiet", quiet, "No progress line");
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    // Under mpirun every rank parses the same line: rank 0 alone prints, all exit alike.
    return (ranks.root() ? app.exit(e) : e.get_exit_code()) == 0 ? 0 : 2;
  }
  if (atlas.referenceThreads > 0 && jobs > 1) {
    if (ranks.root()) {
      std::cerr << "jello-scaling: error: --atlas-reference-threads needs --jobs 1 (with several "
                   "jobs each holds a CPU)\n";
    }
    return 2;
  }
  // The tree as the run starts: the code that ran (outputs written later do not count).
  const nlohmann::json context = runContext(argc, argv);
  // The output directory is made and checked before the (long) run.
  if (!ranks.prepareOutput("jello-scaling", outDir, name)) return 1;
  atlas.referenceDir = referenceDir;
  if (!referenceDir.empty() && !ranks.prepareOutput("jello-scaling", referenceDir, "reference")) {
    return 1;
  }
  if (quick) {
    if (app.count("--n") == 0) ns = {6, 8};
    if (app.count("--budget") == 0) budget = 0.3;
    if (app.count("--atlas-k") == 0 && app.count("--no-atlas") == 0) atlasK = {1e3, 1e5};
    if (app.count("--atlas-n") == 0) atlasN = {8};
    atlas.halvings = 4;
  }
  if (noGrid) ns.clear();
  const AtlasScene scene = *parseAtlasScene(atlasSceneName);
  // The atlas's points, the costliest (largest N, then k) first; each computes its reference.
  std::vector<std::pair<double, int>> atlasPoints;
  for (int n : atlasN) {
    for (double ak : atlasK) atlasPoints.emplace_back(ak, n);
  }
  std::stable_sort(atlasPoints.begin(), atlasPoints.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first > b.first;
  });
  CsvTable atlasRows = atlasTable();

  std::vector<Task> tasks;
  for (int n : ns) {
    for (IntegratorKind kind : integratorsOf({IntegratorFamily::Explicit})) {
      tasks.push_back({n, kind});
    }
    for (IntegratorKind kind : scalingImplicitIntegrators()) {
      for (LinearSolverKind solver : {LinearSolverKind::Cholmod, LinearSolverKind::Cg}) {
        if (isAdaptive(kind) && solver == LinearSolverKind::Cholmod && n > cvodeDirectMaxN) {
          continue;
        }
        tasks.push_back({n, kind, solver});
      }
    }
  }
  // Largest first, so a parallel run does not end on one long point.
  std::stable_sort(tasks.begin(), tasks.end(),
                   [](const Task& a, const Task& b) { return a.n > b.n; });

  CsvTable table({"n", "points", "unknowns", "integrator", "linear_solver", "k_N_per_m",
                  "w_max_rad_per_s", "dt_s", "steps", "simulated_s", "wall_s",
                  "wall_per_simulated_s", "assemble_per_simulated_s", "factor_per_simulated_s",
                  "solve_per_simulated_s", "factorizations"});
  const auto started = Clock::now();
  const bool ok = ranks.run(
      "jello-scaling", int(tasks.size() + atlasPoints.size()), jobs, "points", !quiet,
      [&](int i) {
        if (i >= int(tasks.size())) {
          const auto [ak, an] = atlasPoints[static_cast<std::size_t>(i) - tasks.size()];
          const World w = atlasScene(ak, an, scene);
          const AtlasReference reference = atlasReference(w, ak, scene, atlas);
          for (IntegratorKind kind : atlasIntegrators(quick)) {
            atlasPoint(w, ak, an, kind, reference, atlas, atlasRows);
          }
          return;
        }
        const Task& t = tasks[static_cast<std::size_t>(i)];
        SceneSpec spec = vibratingStiffCube(k);
        spec.cubeResolution = t.n;
        World w = buildWorld(spec);
        const double wMax = maxAngularFrequency(Model(w), initialState(w));
        const double damping = w.kElastic > 0.0 ? w.dElastic / w.kElastic : 0.0;
        double dt = implicitDt;
        if (isExplicit(t.kind)) dt = 0.9 * predictedThreshold(t.kind, wMax, damping);
        SolverOptions options;
        options.implicit.linearSolver = options.cvode.linearSolver = t.solver;
        options.cvode.rtol = rtol;
        Simulation sim(w, t.kind, dt, options);
        const auto t0 = Clock::now();
        double wall = 0.0;
        // Whole steps until the budget is spent (at least one), at most 1 simulated second.
        while (sim.steps() == 0 || (wall < budget && sim.state().t < 1.0)) {
          if (StepResult r = sim.step(); !r.ok) throw std::runtime_error(r.message);
          wall = std::chrono::duration<double>(Clock::now() - t0).count();
        }
        const double simulated = sim.state().t;
        const Integrator& integ = sim.integrator();
        const bool split = !isExplicit(t.kind);
        const auto perSecond = [&](const char* stat) {
          return split ? findStatistic(integ.statistics(), stat).value_or(std::nan("")) / simulated
                       : std::nan("");
        };
        table.add({long(t.n), long(w.numPoints()), long(3 * w.numPoints()),
                   std::string(integratorName(t.kind)),
                   std::string(split ? linearSolverName(t.solver) : "none"), k, wMax, dt,
                   sim.steps(), simulated, wall, wall / simulated, perSecond("assemble_time_s"),
                   perSecond("factor_time_s"), perSecond("solve_time_s"),
                   split
                       ? findStatistic(integ.statistics(), "factorizations").value_or(std::nan(""))
                       : std::nan("")});
      },
      {&table, &atlasRows});
  if (!ok) return 1;
  nlohmann::json sidecar = context;
  sidecar["program"] = "jello-scaling";
  sidecar["parameters"] = {
      {"n", ns},
      {"k_N_per_m", k},
      {"scene", "stiff cube stretched 5% along x, spinning 2 rad/s, c = 0.25 N*s/m"},
      {"explicit_dt", "0.9 times the predicted stability limit"},
      {"implicit_dt_s", implicitDt},
      {"cvode_rtol", rtol},
      {"cvode_cholmod_max_n", cvodeDirectMaxN},
      {"budget_s", budget},
      {"atlas",
       {{"k_N_per_m", atlasK},
        {"n", atlasN},
        {"scene_name", atlasSceneName},
        {"scene", describe(scene)},
        {"time_s", atlas.time},
        {"sample_interval_s", atlas.interval},
        {"tolerance_m", atlas.tolerance},
        {"visible_motion",
         "the least-squares affine map of the rest lattice, compared at the 8 corners"},
        {"reference", "rk4"},
        {"reference_h_w_max", atlas.referenceHw},
        {"reference_dir", referenceDir},
        {"reference_threads", atlas.referenceThreads},
        {"run_budget_s", atlas.runBudget},
        {"steps_tried", atlas.halvings},
        {"explicit_start", "0.9 times the predicted limit"},
        {"implicit_start_s", atlas.interval},
        {"integrators",
         [&] {
           std::vector<std::string> names;
           for (IntegratorKind kind : atlasIntegrators(quick))
             names.emplace_back(integratorName(kind));
           return names;
         }()}}},
      {"jobs", jobs},
      {"quick", quick}};
  sidecar["wall_time_s"] = std::chrono::duration<double>(Clock::now() - started).count();
  const std::filesystem::path dir = outDir;
  if (!ranks.writeOutput("jello-scaling", dir, name, table, sidecar, {{"atlas", &atlasRows}})) {
    return 1;
  }
  if (!quiet && ranks.root()) {
    std::printf("wrote %zu rows to %s (%.1f s)\n", table.rows(), (dir / (name + ".csv")).c_str(),
                sidecar["wall_time_s"].get<double>());
  }
  return 0;
}
