// jello-scaling: wall time per simulated second against cube resolution N, for every
// integrator at a fixed stiffness; for implicit and cvode with CHOLMOD and with CG, the
// factorization and the solves split out. The scene is the stiff cube of work-precision
// (k = 10^4 by default, stretched 5% and spinning) resampled to N^3 points: the mass per point
// and the stiffness per spring stay, so w_max, and the explicit methods' stable step, stay too.
//   jello-scaling [--quick] [--n LIST] [--budget S] [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "experiments/common/signal_handler.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/ranks.h"
#include "experiments/studies/run_context.h"
#include "experiments/studies/stability_analysis.h"
#include "solvers/simulation.h"
#include "solvers/solver_threads.h"
#include "src/finite_options.h"
#include "src/out_of_memory.h"
#include "src/scene_builder.h"

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
  app.add_flag("--quick", quick, "CI: N = 6 and 8, 0.3 s per point");
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
  if (!ranks.prepareOutput("jello-scaling", outDir, name)) return 1;
  if (quick) {
    if (app.count("--n") == 0) ns = {6, 8};
    if (app.count("--budget") == 0) budget = 0.3;
  }

  std::vector<Task> tasks;
  for (int n : ns) {
    for (IntegratorKind kind :
         {IntegratorKind::Euler, IntegratorKind::Symplectic, IntegratorKind::RK4}) {
      tasks.push_back({n, kind});
    }
    for (IntegratorKind kind : {IntegratorKind::Implicit, IntegratorKind::Cvode}) {
      for (LinearSolverKind solver : {LinearSolverKind::Cholmod, LinearSolverKind::Cg}) {
        if (kind == IntegratorKind::Cvode && solver == LinearSolverKind::Cholmod &&
            n > cvodeDirectMaxN) {
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
      "jello-scaling", int(tasks.size()), jobs, "points", !quiet,
      [&](int i) {
        const Task& t = tasks[static_cast<std::size_t>(i)];
        SceneSpec spec = vibratingStiffCube(k);
        spec.cubeResolution = t.n;
        World w = buildWorld(spec);
        const double wMax = maxAngularFrequency(Model(w), initialState(w));
        const double damping = w.kElastic > 0.0 ? w.dElastic / w.kElastic : 0.0;
        double dt = implicitDt;
        if (t.kind != IntegratorKind::Implicit && t.kind != IntegratorKind::Cvode) {
          dt = 0.9 * predictedThreshold(t.kind, wMax, damping);
        }
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
        const bool split = t.kind == IntegratorKind::Implicit || t.kind == IntegratorKind::Cvode;
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
      {&table});
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
      {"jobs", jobs},
      {"quick", quick}};
  sidecar["wall_time_s"] = std::chrono::duration<double>(Clock::now() - started).count();
  const std::filesystem::path dir = outDir;
  if (!ranks.writeOutput("jello-scaling", dir, name, table, sidecar)) return 1;
  if (!quiet && ranks.root()) {
    std::printf("wrote %zu rows to %s (%.1f s)\n", table.rows(), (dir / (name + ".csv")).c_str(),
                sidecar["wall_time_s"].get<double>());
  }
  return 0;
}
