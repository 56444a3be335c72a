// jello-work-precision: error against wall time for every integrator across time steps (cvode:
// across tolerances, at maximum order 2 and 5), on a soft scene (jello.w, before its first
// contact) and a stiff one (the free cube at k = 10^4, stretched 5% and spinning), against a
// converged reference; and backward Euler's artificial damping on the undamped stiff cube.
//   jello-work-precision [--quick] [--levels N] [--out-dir DIR] [--jobs N]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "experiments/common/signal_handler.h"
#include "experiments/studies/csv_table.h"
#include "experiments/studies/parallel_for.h"
#include "experiments/studies/run_context.h"
#include "experiments/studies/stability_analysis.h"
#include "solvers/simulation.h"
#include "solvers/solver_threads.h"
#include "src/finite_options.h"
#include "src/out_of_memory.h"
#include "src/scene_builder.h"
#include "src/world_reader.h"

namespace {

using namespace jello;
using namespace jello::experiments;
using Clock = std::chrono::steady_clock;

// vibratingStiffCube with the given damping and spin, centred in the box.
World stiffScene(double k, double damping, double spin = 2.0) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = damping;
  spec.spin = spin;
  World w = buildWorld(spec);
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};
  return w;
}

struct Scene {
  std::string name;
  World world;
  double time;          // s, where errors are measured
  double dampingRatio;  // s, c/k, for the explicit methods' predicted limits
  double wMax;          // rad/s at the start
  State reference;
  double referenceCheck = 0.0;  // m, |cvode reference - rk4 at a tiny step|
};

struct Run {
  double seconds = 0.0;
  long steps = 0;
  State end;
};

Run simulate(const World& w, IntegratorKind kind, double dt, double time,
             const SolverOptions& options) {
  Simulation sim(w, kind, dt, options);
  const long steps = std::lround(time / dt);
  const auto t0 = Clock::now();
  for (long i = 0; i < steps; ++i) {
    if (StepResult r = sim.step(); !r.ok) {
      throw std::runtime_error(std::string(integratorName(kind)) + ": " + r.message);
    }
  }
  return {std::chrono::duration<double>(Clock::now() - t0).count(), steps, sim.state()};
}

double positionError(const State& a, const State& b) {
  const int n = a.numPoints();
  double worst = 0.0;
  for (int p = 0; p < n; ++p) worst = std::max(worst, norm(a.position(p) - b.position(p)));
  return worst;
}

// A task of the grid: one run and how to record it.
struct Task {
  std::size_t scene;
  IntegratorKind kind;
  double dt = 0.0;    // s (cvode: the output interval, the whole span)
  double rtol = 0.0;  // cvode only
  int maxOrder = 0;   // cvode only
};

}  // namespace

int main(int argc, char** argv) {
  jello::exitCleanlyWhenOutOfMemory("jello-work-precision");
  jello::ignoreBrokenPipes("jello-work-precision");
  applySolverThreadSettings(argv);
  int levels = 7, jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  double stiffK = 1e4;
  bool quick = false, quiet = false;
  std::string outDir = "experiments/results", name = "work_precision", worldsDir = JELLO_WORLDS_DIR;
  CLI::App app{
      "jello-work-precision: error against wall time per integrator, and backward "
      "Euler's artificial damping"};
  app.add_option("--levels", levels, "Time steps per integrator (halving from its largest)")
      ->check(jello::cli::range(2, 12))
      ->capture_default_str();
  app.add_option("--stiff-k", stiffK, "Stiffness of the stiff scene, N/m")
      ->check(jello::cli::positive())
      ->capture_default_str();
  app.add_option("--worlds", worldsDir, "Directory holding jello.w")->capture_default_str();
  app.add_option("--jobs", jobs, "Runs in parallel")
      ->check(jello::cli::range(1, 256))
      ->capture_default_str();
  app.add_option("--out-dir", outDir, "Directory for NAME.csv and NAME.json")
      ->capture_default_str();
  app.add_option("--name", name, "File name stem")->capture_default_str();
  app.add_flag(
      "--quick", quick,
      "CI: the soft scene only, 3 levels per method in its asymptotic range, 3 tolerances");
  app.add_flag("--quiet", quiet, "No progress line");
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  // The tree as the run starts: the code that ran (outputs written later do not count).
  const nlohmann::json context = runContext(argc, argv);
  // The output directory is made and checked before the (long) run.
  if (!prepareOutputDirectory("jello-work-precision", outDir, name)) return 1;
  if (quick && app.count("--levels") == 0) levels = 3;
  const std::vector<double> rtols =
      quick ? std::vector<double>{1e-3, 1e-5, 1e-7}
            : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};

  std::vector<Scene> scenes;
  SolverOptions referenceOptions;
  referenceOptions.cvode.rtol = 1e-11;
  referenceOptions.cvode.atolPosition = referenceOptions.cvode.atolVelocity = 1e-14;
  referenceOptions.cvode.maxStepsPerCall = 100000000;
  try {
    // jello.w is measured at 0.04 s, before its first contact (about 0.05 s): contact onset
    // is not smooth and would cap every method's order.
    World soft = readWorld(std::filesystem::path(worldsDir) / "jello.w");
    std::vector<std::tuple<std::string, World, double>> list{{"soft", soft, 0.04}};
    if (!quick) list.emplace_back("stiff", stiffScene(stiffK, 0.25), 0.04);
    for (auto& [label, w, time] : list) {
      const Model model(w);
      Scene s{label,
              w,
              time,
              w.kElastic > 0 ? w.dElastic / w.kElastic : 0.0,
              maxAngularFrequency(model, initialState(w)),
              {},
              0.0};
      s.reference = simulate(w, IntegratorKind::Cvode, time, time, referenceOptions).end;
      // The reference checked against RK4 at a step far below its limit.
      const double tiny = time / std::pow(2.0, std::ceil(std::log2(time * s.wMax / 0.05)));
      s.referenceCheck =
          positionError(simulate(w, IntegratorKind::RK4, tiny, time, {}).end, s.reference);
      scenes.push_back(std::move(s));
    }
  } catch (const std::exception& e) {
    std::cerr << "jello-work-precision: error: " << e.what() << '\n';
    return 1;
  }

  std::vector<Task> tasks;
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    for (IntegratorKind kind : {IntegratorKind::Euler, IntegratorKind::Symplectic,
                                IntegratorKind::RK4, IntegratorKind::Implicit}) {
      // The largest step: 0.9 of the predicted limit (implicit: 0.01 s), as a whole fraction
      // 1/2^j of the span. --quick starts the first-order methods where h w_max <= 0.5, in the
      // asymptotic range where their order shows, and keeps the runs short.
      double limit = predictedThreshold(kind, scenes[s].wMax, scenes[s].dampingRatio);
      limit = std::isinf(limit) ? 0.01 : 0.9 * limit;
      if (quick && kind != IntegratorKind::RK4) limit = std::min(limit, 0.5 / scenes[s].wMax);
      const int count = kind == IntegratorKind::Implicit && !quick ? levels + 2 : levels;
      double dt = scenes[s].time;
      while (dt > limit) dt /= 2.0;
      for (int l = 0; l < count; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
    }
    for (int order : {2, 5}) {
      for (double rtol : rtols) {
        // BDF2 at the tightest tolerance takes minutes on the stiff cube; order 5 covers it.
        if (order == 2 && rtol < 1e-7 && scenes[s].name == "stiff") continue;
        tasks.push_back({s, IntegratorKind::Cvode, scenes[s].time, rtol, order});
      }
    }
  }
  // Backward Euler's artificial damping: the stiff cube without any damping (and without spin,
  // so all its energy is vibration) keeps its energy exactly; whatever the implicit step loses
  // is numerical. Measured over 0.02 s: over longer spans every step size removes almost all.
  const World undamped = stiffScene(stiffK, 0.0, 0.0);
  const double dampingTime = 0.02;
  std::vector<double> dampingSteps;
  for (double dt = 0.01; dampingSteps.size() < std::size_t(quick ? 2 : 8); dt /= 2.0) {
    dampingSteps.push_back(dt);
  }

  CsvTable table({"scene", "integrator", "cvode_max_order", "dt_s", "rtol", "steps", "wall_time_s",
                  "position_error_m", "energy_relative_error"});
  CsvTable damping({"scene", "integrator", "dt_s", "h_w_max", "steps", "energy_start_J",
                    "energy_end_J", "energy_loss_J_per_s", "energy_decay_rate_per_s"});
  const int total = int(tasks.size() + dampingSteps.size());
  const auto started = Clock::now();
  try {
    parallelFor(total, jobs, "runs", !quiet, [&](int i) {
      if (i >= int(tasks.size())) {
        const double dt = dampingSteps[static_cast<std::size_t>(i) - tasks.size()];
        const Model model(undamped);
        const double e0 = model.energy(initialState(undamped)).total();
        const Run r = simulate(undamped, IntegratorKind::Implicit, dt, dampingTime, {});
        const double e1 = model.energy(r.end).total();
        damping.add({std::string("stiff_undamped"), std::string("implicit"), dt,
                     dt * maxAngularFrequency(model, initialState(undamped)), r.steps, e0, e1,
                     (e0 - e1) / dampingTime, std::log(e0 / e1) / dampingTime});
        return;
      }
      const Task& t = tasks[static_cast<std::size_t>(i)];
      const Scene& s = scenes[t.scene];
      SolverOptions options;
      if (t.kind == IntegratorKind::Cvode) {
        options.cvode.rtol = t.rtol;
        options.cvode.maxOrder = t.maxOrder;
        options.cvode.maxStepsPerCall = 100000000;
      }
      const Run r = simulate(s.world, t.kind, t.dt, s.time, options);
      const Model model(s.world);
      const double eRef = model.energy(s.reference).total(), e = model.energy(r.end).total();
      table.add({s.name, std::string(integratorName(t.kind)), long(t.maxOrder), t.dt, t.rtol,
                 r.steps, r.seconds, positionError(r.end, s.reference),
                 std::abs(e - eRef) / std::abs(eRef)});
    });
  } catch (const std::exception& e) {
    std::cerr << "jello-work-precision: error: " << e.what() << '\n';
    return 1;
  }

  nlohmann::json sidecar = context;
  sidecar["program"] = "jello-work-precision";
  nlohmann::json sceneInfo = nlohmann::json::array();
  for (const Scene& s : scenes) {
    sceneInfo.push_back({{"scene", s.name},
                         {"time_s", s.time},
                         {"k_N_per_m", s.world.kElastic},
                         {"c_Ns_per_m", s.world.dElastic},
                         {"w_max_rad_per_s", s.wMax},
                         {"reference", "cvode rtol 1e-11 atol 1e-14, order 5"},
                         {"reference_vs_rk4_tiny_step_m", s.referenceCheck}});
  }
  sidecar["parameters"] = {{"scenes", sceneInfo},
                           {"levels", levels},
                           {"cvode_rtols", rtols},
                           {"damping_scene",
                            {{"k_N_per_m", stiffK},
                             {"c_Ns_per_m", 0.0},
                             {"time_s", dampingTime},
                             {"pose", "stretched 5% along x, at rest"}}},
                           {"jobs", jobs},
                           {"quick", quick},
                           {"position_error", "max over points of |x - x_ref| at time_s"},
                           {"energy_relative_error", "|E - E_ref| / |E_ref| at time_s"}};
  sidecar["wall_time_s"] = std::chrono::duration<double>(Clock::now() - started).count();
  const std::filesystem::path dir = outDir;
  if (!writeResults("jello-work-precision", dir, name, table, sidecar, {{"damping", &damping}})) {
    return 1;
  }
  if (!quiet) {
    std::printf("wrote %zu + %zu rows to %s (%.1f s)\n", table.rows(), damping.rows(), dir.c_str(),
                sidecar["wall_time_s"].get<double>());
  }
  return 0;
}
