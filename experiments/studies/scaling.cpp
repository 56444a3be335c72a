// jello-scaling: wall time per simulated second against cube resolution N, for every
// integrator at a fixed stiffness; for implicit and cvode with CHOLMOD and with CG, the
// factorization and the solves split out. The scene is the stiff cube of work-precision
// (k = 10^4 by default, stretched 5% and spinning) resampled to N^3 points: the mass per point
// and the stiffness per spring stay, so w_max, and the explicit methods' stable step, stay too.
// Also the crossover atlas (atlas.h): over k and N, each integrator's cost at the largest step
// that keeps the visible motion within a tolerance.
//   jello-scaling [--quick] [--n LIST] [--budget S] [--atlas-k LIST] [--atlas-n LIST]
//                 [--atlas-scene falling|free|slide] [--atlas-contact soft|k|20k|barrier]
//                 [--atlas-references DIR] [--atlas-trace]
//                 [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "experiments/studies/atlas.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study.h"
#include "experiments/studies/study_integrators.h"
#include "solvers/simulation.h"
#include "src/base/finite_options.h"
#include "src/world/scene_builder.h"

namespace {

using namespace jello;
using namespace jello::experiments;
using Clock = std::chrono::steady_clock;

struct Options {
  std::vector<int> ns{8, 12, 16, 24, 32};
  double k = 1e4, budget = 3.0, implicitDt = 0.01, rtol = 1e-3;
  int cvodeDirectMaxN = 16;
  bool noGrid = false;
  // The whole atlas is hours of CPU at N = 32 (scripts/run-experiments.sh runs N = 8; a
  // cluster runs the rest under mpirun).
  std::vector<double> atlasK{1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8};
  std::vector<int> atlasN{8, 16, 32};
  AtlasSetup atlas;
  std::string atlasScene = "falling";
  std::string atlasContact = "soft";
  std::string referenceDir;
  bool atlasTrace = false;
  bool referencesOnly = false;
  std::vector<std::string> atlasIntegratorNames;  // empty: every integrator (--quick: its picks)
  std::vector<IntegratorKind> atlasKinds;
};

// A point of the resolution grid.
struct Task {
  int n;
  IntegratorKind kind;
  LinearSolverKind solver = LinearSolverKind::Cholmod;  // implicit, cvode
};

void addGridOptions(CLI::App& app, Options& opt) {
  app.add_option("--n", opt.ns, "Cube resolutions")
      ->check(jello::cli::range(2, 64))
      ->delimiter(',');
  app.add_option("--k", opt.k, "Spring stiffness, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  // Bounded as jello-stability's times and steps are (issue 41, item 6): a budget of 1e308 s
  // never ends, a step of 4.9e-324 s never moves the clock.
  app.add_option("--budget", opt.budget, "Wall seconds to run each point for (at least one step)")
      ->check(jello::cli::range(1e-3, 1e6))
      ->capture_default_str();
  app.add_option("--implicit-dt", opt.implicitDt,
                 "Time step of implicit, output interval of cvode, s")
      ->check(jello::cli::range(1e-9, 1.0))
      ->capture_default_str();
  app.add_option("--rtol", opt.rtol, "cvode's relative tolerance")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--cvode-cholmod-max-n", opt.cvodeDirectMaxN,
                 "Largest N for cvode with CHOLMOD (one output interval there needs several "
                 "factorizations of minutes each at N = 32)")
      ->capture_default_str();
  app.add_flag("--no-grid", opt.noGrid,
               "Leave the resolution grid out: the atlas alone (NAME.csv holds only its header)");
}

void addAtlasOptions(CLI::App& app, Options& opt) {
  app.add_option("--atlas-k", opt.atlasK,
                 "The atlas's stiffnesses, N/m (default 1e2 to 1e8 by decades; --no-atlas: none)")
      ->check(jello::cli::positive())
      ->delimiter(',');
  app.add_option("--atlas-n", opt.atlasN, "The atlas's cube resolutions (default 8, 16, 32)")
      ->check(jello::cli::range(2, 64))
      ->delimiter(',');
  app.add_option("--atlas-tolerance", opt.atlas.tolerance,
                 "The atlas's accuracy on the visible motion, m at the corners")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--atlas-scene", opt.atlasScene,
                 "The atlas's scene: falling (thrown, spinning, onto the floor under gravity), "
                 "free (the same throw and spin without gravity: no contact) or slide (thrown down "
                 "an incline with friction, sliding to rest; its window is 2 s)")
      ->check(CLI::IsMember(sceneNames()))
      ->capture_default_str();
  app.add_option("--atlas-contact", opt.atlasContact,
                 "The falling scene's floor, the slide scene's incline: penalty contact of the "
                 "course's 400 N/m (soft), as stiff as the springs (k) or 20 times stiffer (20k), "
                 "or the log barrier with kappa = k and dhat 5 mm (barrier)")
      ->check(CLI::IsMember(contactNames()))
      ->capture_default_str();
  app.add_option("--atlas-integrators", opt.atlasIntegratorNames,
                 "The atlas's integrators (default all; --quick: five): " + namedIntegratorsHelp())
      ->delimiter(',');
  app.add_option(
         "--atlas-steps-tried", opt.atlas.halvings,
         "Steps tried per integrator, each half the last (cvode: tolerances, each a tenth), "
         "while the budget allows (--quick: 4)")
      ->check(jello::cli::range(1, 30))
      ->capture_default_str();
  app.add_option("--atlas-first-step", opt.atlas.firstStep,
                 "First step of the implicit and projective methods, s: the sample interval 0.02 "
                 "over a whole number (default the interval; with --atlas-trace, the step traced)")
      ->check(jello::cli::range(1e-9, 1.0));
  app.add_option("--atlas-budget", opt.atlas.runBudget,
                 "Wall seconds of one atlas run beyond which smaller steps are not tried")
      ->check(jello::cli::range(1e-3, 1e6))
      ->capture_default_str();
  app.add_option("--atlas-references", opt.referenceDir,
                 "Directory the atlas's RK4 references are read from, or written to once computed "
                 "(with their last state every --atlas-checkpoint s meanwhile: a stopped run "
                 "resumes there)");
  app.add_option("--atlas-checkpoint", opt.atlas.checkpoint,
                 "Wall seconds between the saved states of a reference being computed")
      ->check(jello::cli::range(1e-3, 1e6))
      ->capture_default_str();
  app.add_option("--atlas-reference-threads", opt.atlas.referenceThreads,
                 "Threads of the model while a reference is computed, with --jobs 1 (default: the "
                 "runs' own, JELLO_THREADS or the CPUs)")
      ->check(jello::cli::range(1, 64));
  app.add_flag_function(
      "--no-atlas", [&opt](std::int64_t) { opt.atlasK.clear(); }, "Leave the atlas out");
  app.add_flag("--atlas-trace", opt.atlasTrace,
               "Instead of the atlas's search, the visible motion over time (NAME_trace.csv): the "
               "reference's, and each integrator's at its largest step (cvode: its loosest "
               "tolerance)");
  app.add_flag("--atlas-references-only", opt.referencesOnly,
               "Compute each atlas point's RK4 reference and its check into --atlas-references "
               "and run no integrator, the resolution grid's neither (the references of a long "
               "atlas on every core first, the timed runs later: a rerun reads them); the CSVs "
               "then have no rows");
}

void applyDefaults(const Study& study, Options& opt) {
  opt.atlas.referenceDir = opt.referenceDir;
  if (study.quick) {
    if (!study.given("--n")) opt.ns = {6, 8};
    if (!study.given("--budget")) opt.budget = 0.3;
    if (!study.given("--atlas-k") && !study.given("--no-atlas")) opt.atlasK = {1e3, 1e5};
    if (!study.given("--atlas-n")) opt.atlasN = {8};
    if (!study.given("--atlas-steps-tried")) opt.atlas.halvings = 4;
  }
  if (opt.noGrid) opt.ns.clear();
}

// The resolution grid, largest first, so a parallel run does not end on one long point.
std::vector<Task> gridTasks(const Options& opt) {
  std::vector<Task> tasks;
  for (int n : opt.ns) {
    for (IntegratorKind kind : integratorsOf({IntegratorFamily::Explicit})) {
      tasks.push_back({n, kind});
    }
    for (IntegratorKind kind : scalingImplicitIntegrators()) {
      for (LinearSolverKind solver : {LinearSolverKind::Cholmod, LinearSolverKind::Cg}) {
        if (isAdaptive(kind) && solver == LinearSolverKind::Cholmod && n > opt.cvodeDirectMaxN) {
          continue;
        }
        tasks.push_back({n, kind, solver});
      }
    }
  }
  std::stable_sort(tasks.begin(), tasks.end(),
                   [](const Task& a, const Task& b) { return a.n > b.n; });
  return tasks;
}

// The atlas's points, the costliest (largest N, then k) first; each computes its reference.
std::vector<std::pair<double, int>> atlasPoints(const Options& opt) {
  std::vector<std::pair<double, int>> points;
  for (int n : opt.atlasN) {
    for (double ak : opt.atlasK) points.emplace_back(ak, n);
  }
  std::stable_sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first > b.first;
  });
  return points;
}

CsvTable scalingTable() {
  return CsvTable({"n", "points", "unknowns", "integrator", "linear_solver", "k_N_per_m",
                   "w_max_rad_per_s", "dt_s", "steps", "simulated_s", "wall_s",
                   "wall_per_simulated_s", "assemble_per_simulated_s", "factor_per_simulated_s",
                   "solve_per_simulated_s", "factorizations"});
}

// One point of the grid: whole steps until the budget is spent (at least one), at most 1
// simulated second; the implicit ones' assembly, factorizations and solves apart.
void runTask(const Task& t, const Options& opt, CsvTable& table) {
  SceneSpec spec = vibratingStiffCube(opt.k);
  spec.cubeResolution = t.n;
  World w = buildWorld(spec);
  const double wMax = maxAngularFrequency(Model(w), initialState(w));
  const double damping = w.kElastic > 0.0 ? w.dElastic / w.kElastic : 0.0;
  double dt = opt.implicitDt;
  if (isExplicit(t.kind)) dt = 0.9 * predictedThreshold(t.kind, wMax, damping);
  SolverOptions options;
  options.implicit.linearSolver = options.cvode.linearSolver = t.solver;
  options.cvode.rtol = opt.rtol;
  Simulation sim(w, t.kind, dt, options);
  const auto t0 = Clock::now();
  double wall = 0.0;
  while (sim.steps() == 0 || (wall < opt.budget && sim.state().t < 1.0)) {
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
             std::string(split ? linearSolverName(t.solver) : "none"), opt.k, wMax, dt, sim.steps(),
             simulated, wall, wall / simulated, perSecond("assemble_time_s"),
             perSecond("factor_time_s"), perSecond("solve_time_s"),
             split ? findStatistic(integ.statistics(), "factorizations").value_or(std::nan(""))
                   : std::nan("")});
}

// One point of the atlas: its reference, then each integrator's search (--atlas-trace: each
// one's run at its largest step). A point whose reference fails is reported without one
// (outcome no_reference) and the run goes on.
void runAtlasPoint(double ak, int an, AtlasScene scene, AtlasContact contact, const Options& opt,
                   CsvTable& atlasRows, CsvTable& traceRows, CsvTable& triesRows) {
  const World w = atlasScene(ak, an, scene, contact);
  std::optional<AtlasReference> found;
  try {
    found = atlasReference(w, ak, scene, opt.atlas, contact);
  } catch (const AtlasReferenceFailed& e) {
    std::fprintf(stderr, "jello-scaling: k = %g, N = %d: %s\n", ak, an, e.what());
    const double wMax = atlasMaxFrequency(w, scene);
    for (IntegratorKind kind : opt.atlasKinds) {
      atlasNoReference(ak, an, wMax, kind, atlasRows);
    }
    return;
  }
  if (opt.referencesOnly) return;
  const AtlasReference& reference = *found;
  if (opt.atlasTrace) atlasTrace(w, ak, an, std::nullopt, reference, opt.atlas, traceRows);
  for (IntegratorKind kind : opt.atlasKinds) {
    if (opt.atlasTrace) {
      atlasTrace(w, ak, an, kind, reference, opt.atlas, traceRows);
    } else {
      atlasPoint(w, ak, an, kind, reference, opt.atlas, atlasRows, &triesRows);
    }
  }
}

nlohmann::json scalingParameters(const Options& opt, const Study& study, const AtlasScene& scene,
                                 AtlasContact contact) {
  std::vector<std::string> atlasNames;
  for (IntegratorKind kind : opt.atlasKinds) {
    atlasNames.emplace_back(integratorName(kind));
  }
  const AtlasSetup& atlas = opt.atlas;
  return {{"n", opt.ns},
          {"k_N_per_m", opt.k},
          {"scene", "stiff cube stretched 5% along x, spinning 2 rad/s, c = 0.25 N*s/m"},
          {"explicit_dt", "0.9 times the predicted stability limit"},
          {"implicit_dt_s", opt.implicitDt},
          {"cvode_rtol", opt.rtol},
          {"cvode_cholmod_max_n", opt.cvodeDirectMaxN},
          {"budget_s", opt.budget},
          {"atlas",
           {{"k_N_per_m", opt.atlasK},
            {"n", opt.atlasN},
            {"scene_name", opt.atlasScene},
            {"scene", describe(scene)},
            {"contact", contactName(contact)},
            {"k_collision", contact == AtlasContact::Soft      ? "400 N/m"
                            : contact == AtlasContact::AsStiff ? "k"
                            : contact == AtlasContact::Stiffer ? "20 k"
                                                               : "barrier: kappa = k, dhat 5 mm"},
            {"w_max", scene == AtlasScene::Free ? "the start's"
                      : scene == AtlasScene::Falling
                          ? "the larger of the start's and the cube's resting on the floor, "
                            "contact springs included (the barrier's where it carries twice the "
                            "weight of a column of N points)"
                          : "the largest of the start's, the cube's resting on the incline, "
                            "contact springs included, and static friction's damping rate 2 mu "
                            "lambda / (m eps), lambda twice the weight of a column of N points"},
            {"time_s", atlas.time},
            {"sample_interval_s", atlas.interval},
            {"tolerance_m", atlas.tolerance},
            {"visible_motion",
             "the least-squares affine map of the rest lattice, compared at the 8 corners"},
            {"reference", "rk4"},
            {"reference_h_w_max", atlas.referenceHw},
            {"reference_check_max_of_tolerance", atlas.referenceCheck},
            {"reference_refinements_max", atlas.referenceRefinements},
            {"reference_dir", opt.referenceDir},
            {"reference_threads", atlas.referenceThreads},
            {"run_budget_s", atlas.runBudget},
            {"steps_tried", atlas.halvings},
            {"implicit_start_s", atlas.firstStep > 0.0 ? atlas.firstStep : atlas.interval},
            {"explicit_start", "0.9 times the predicted limit"},
            {"integrators", atlasNames}}},
          {"jobs", study.jobs},
          {"quick", study.quick}};
}

// What the options cannot mean together ("" when nothing), the atlas's integrators set.
std::string checkOptions(const Study& study, Options& opt) {
  if (opt.atlas.referenceThreads > 0 && study.jobs > 1) {
    return "--atlas-reference-threads needs --jobs 1 (with several jobs each holds a CPU)";
  }
  auto named = namedIntegrators(opt.atlasIntegratorNames, atlasIntegrators(study.quick));
  if (const std::string* unknown = std::get_if<std::string>(&named)) {
    return "--atlas-integrators: unknown integrator '" + *unknown +
           "' (known: " + namedIntegratorsHelp() + ")";
  }
  opt.atlasKinds = std::get<std::vector<IntegratorKind>>(std::move(named));
  if (const double first = opt.atlas.firstStep; first > 0.0) {
    const double ratio = opt.atlas.interval / first;
    if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-6 * ratio) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "--atlas-first-step %g: not the sample interval (%g s) over a whole number",
                    first, opt.atlas.interval);
      return text;
    }
  }
  if (opt.referencesOnly && (opt.referenceDir.empty() || opt.atlasTrace)) {
    return "--atlas-references-only needs --atlas-references DIR (where they are kept) and "
           "no --atlas-trace";
  }
  return opt.atlasScene == "free" && opt.atlasContact != "soft"
             ? "--atlas-contact is the falling scene's floor: the free scene touches nothing"
             : "";
}

}  // namespace

int main(int argc, char** argv) {
  Study study("jello-scaling", "wall time per simulated second against cube resolution", "scaling",
              argc, argv);
  Options opt;
  addGridOptions(study.app(), opt);
  addAtlasOptions(study.app(), opt);
  study.addCommonOptions(
      "CI: N = 6 and 8, 0.3 s per point; the atlas at k = 1e3 and 1e5, N = 8, with symplectic, "
      "rk4, implicit, midpoint and projective, 4 steps tried each",
      "Points run in parallel (1 gives timings free of a neighbour's memory traffic)");
  const auto code = study.start(argc, argv, [&]() { return checkOptions(study, opt); });
  if (code) return *code;
  if (!opt.referenceDir.empty() &&
      !study.ranks().prepareOutput(study.program(), opt.referenceDir, "reference")) {
    return 1;
  }
  applyDefaults(study, opt);
  const AtlasScene scene = *parseAtlasScene(opt.atlasScene);
  const AtlasContact contact = *parseAtlasContact(opt.atlasContact);
  if (scene == AtlasScene::Slide) opt.atlas.time = kSlideTime;
  // References alone: the resolution grid's timed runs are left out too.
  const std::vector<Task> tasks = opt.referencesOnly ? std::vector<Task>{} : gridTasks(opt);
  const std::vector<std::pair<double, int>> points = atlasPoints(opt);

  CsvTable table = scalingTable(), atlasRows = atlasTable(), traceRows = atlasTraceTable(),
           triesRows = atlasTriesTable();
  const bool ok =
      study.run(int(tasks.size() + points.size()), "points",
                [&](int index) {
                  const auto i = static_cast<std::size_t>(index);
                  if (i < tasks.size()) {
                    runTask(tasks[i], opt, table);
                    return;
                  }
                  const auto [ak, an] = points[i - tasks.size()];
                  runAtlasPoint(ak, an, scene, contact, opt, atlasRows, traceRows, triesRows);
                },
                {&table, &atlasRows, &traceRows, &triesRows});
  if (!ok) return 1;
  nlohmann::json parameters = scalingParameters(opt, study, scene, contact);
  parameters["atlas"]["trace"] = opt.atlasTrace;
  parameters["atlas"]["references_only"] = opt.referencesOnly;
  if (opt.atlasTrace) return study.finish(table, parameters, {{"trace", &traceRows}});
  return study.finish(table, parameters, {{"atlas", &atlasRows}, {"tries", &triesRows}});
}
