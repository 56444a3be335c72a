// jello-work-precision: error over whole trajectories against wall time for every integrator
// across time steps (cvode: BDF and Adams across tolerances) on three scenes with contact or
// stiffness in their windows (jello.w for 1 s, a 2 s drop onto the sphere, an undamped spinning
// stiff cube), against a converged reference sampled every interval; timings are medians of
// repeated runs with set-up apart, and the solvers' work is counted. Also backward Euler's
// artificial damping on the undamped stiff cube.
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
#include "experiments/studies/parallel_for.h"
#include "experiments/studies/ranks.h"
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

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// vibratingStiffCube with the given damping and spin, centred in the box.
World stiffScene(double k, double damping, double spin = 2.0) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = damping;
  spec.spin = spin;
  World w = buildWorld(spec);
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};
  return w;
}

// States at t_k = k * interval, k = 0 .. K; a reference also keeps each state's total energy
// and angular momentum (measure()), computed once rather than by every run compared with it.
struct Trajectory {
  double interval = 0.0;
  std::vector<State> states;
  std::vector<double> energy;         // J
  std::vector<Vec3> angularMomentum;  // kg m^2/s
  void measure(const Model& model) {
    energy.clear();
    angularMomentum.clear();
    for (const State& s : states) {
      energy.push_back(model.energy(s).total());
      angularMomentum.push_back(model.angularMomentum(s));
    }
  }
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

// The errors of a run against the reference over the whole window, at every sample.
struct Errors {
  double positionMax = 0.0;         // m, max over samples and points of |x - x_ref|
  double positionRms = 0.0;         // m, RMS over samples of the max over points
  double energyMax = 0.0;           // max over samples of |E - E_ref| / E_ref(0)
  double angularMomentumMax = 0.0;  // max over samples of |L - L_ref| / max |L_ref|
};

class ErrorMeter {
 public:
  // `reference` has been measured (Trajectory::measure) on the same scene.
  ErrorMeter(const Model& model, const Trajectory& reference)
      : model_(model), reference_(reference) {
    energyScale_ = std::abs(reference.energy.front());
    for (const Vec3& l : reference.angularMomentum)
      angularScale_ = std::max(angularScale_, norm(l));
  }
  void sample(std::size_t k, const State& s) {
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
            ? std::max(e_.angularMomentumMax,
                       norm(model_.angularMomentum(s) - reference_.angularMomentum.at(k)) /
                           angularScale_)
            : std::nan("");
  }
  Errors result() const {
    Errors e = e_;
    e.positionRms = samples_ ? std::sqrt(squares_ / double(samples_)) : 0.0;
    return e;
  }

 private:
  const Model& model_;
  const Trajectory& reference_;
  double energyScale_ = 0.0, angularScale_ = 0.0, squares_ = 0.0;
  long samples_ = 0;
  Errors e_;
};

// One timed run over the window: set-up (the Simulation's construction), the first step (where
// the implicit integrators analyse and factor) and every step's time, taken apart from the
// error sampling.
struct Run {
  double setup = 0.0, firstStep = 0.0, steps = 0.0;  // s
  long count = 0;
  long forceEvaluations = 0;
  std::vector<Statistic> statistics;
  std::string failure;  // empty when every step succeeded
  Errors errors;
  Trajectory trajectory;  // when asked to keep it
};

Run run(const World& w, IntegratorKind kind, double dt, double time, double interval,
        const SolverOptions& options, const Trajectory* reference, bool keep = false) {
  Run r;
  const auto t0 = Clock::now();
  Simulation sim(w, kind, dt, options);
  r.setup = since(t0);
  const long perSample = std::lround(interval / dt), samples = std::lround(time / interval);
  std::optional<ErrorMeter> meter;
  if (reference) meter.emplace(sim.model(), *reference);
  if (keep) r.trajectory = {interval, {sim.state()}, {}, {}};
  const long forcesBefore = sim.model().counts().springs;
  for (long k = 1; k <= samples && r.failure.empty(); ++k) {
    for (long i = 0; i < perSample; ++i) {
      const auto s0 = Clock::now();
      const StepResult result = sim.step();
      const double seconds = since(s0);
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

constexpr IntegratorKind kImplicitKinds[] = {
    IntegratorKind::Implicit, IntegratorKind::ImplicitLinear, IntegratorKind::Midpoint,
    IntegratorKind::Newmark,  IntegratorKind::Bdf2,           IntegratorKind::Projective};

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
    return app.exit(e) == 0 ? 0 : 2;
  }
  // The tree as the run starts: the code that ran (outputs written later do not count).
  const nlohmann::json context = runContext(argc, argv);
  // The output directory is made and checked before the (long) run.
  if (!ranks.prepareOutput("jello-work-precision", outDir, name)) return 1;
  if (quick && app.count("--levels") == 0) levels = 3;
  if (quick && app.count("--repeats") == 0) repeats = 1;
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
                        stiffScene(stiffK, 0.0), 0.2, 0.05);
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
    for (IntegratorKind kind :
         {IntegratorKind::Euler, IntegratorKind::Symplectic, IntegratorKind::RK4}) {
      // The largest step: the largest interval / 2^j below 0.9 of the predicted limit. --quick
      // starts the first-order methods where h w_max <= 0.5, in the asymptotic range where
      // their order shows, and keeps the runs short.
      double limit = 0.9 * predictedThreshold(kind, scene.wMax, scene.dampingRatio);
      if (limit <= 0.0) continue;  // forward Euler on an undamped scene: never stable
      if (quick && kind != IntegratorKind::RK4) limit = std::min(limit, 0.5 / scene.wMax);
      double dt = interval;
      while (dt > limit) dt /= 2.0;
      for (int l = 0; l < levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
    }
    for (IntegratorKind kind : kImplicitKinds) {
      if (quick && kind != IntegratorKind::Implicit) continue;
      // From the sampling interval (quick: from h w_max <= 0.5, where order 1 shows).
      double dt = interval;
      if (quick) {
        while (dt * scene.wMax > 0.5) dt /= 2.0;
      }
      for (int l = 0; l < levels; ++l, dt /= 2.0) tasks.push_back({s, kind, dt});
    }
    for (CvodeMethod method : {CvodeMethod::Bdf, CvodeMethod::Adams}) {
      if (quick && method == CvodeMethod::Adams) continue;
      for (double rtol : rtols) tasks.push_back({s, IntegratorKind::Cvode, interval, method, rtol});
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
                    "energy_end_J", "energy_loss_J_per_s", "energy_decay_rate_per_s"});
  const int total = int(tasks.size() + dampingSteps.size());
  const auto started = Clock::now();
  const bool ok = ranks.run(
      "jello-work-precision", total, jobs, "runs", !quiet,
      [&](int i) {
        if (i >= int(tasks.size())) {
          const double dt = dampingSteps[static_cast<std::size_t>(i) - tasks.size()];
          const Model model(undamped);
          const double e0 = model.energy(initialState(undamped)).total();
          const Run r =
              run(undamped, IntegratorKind::Implicit, dt, dampingTime, dt, {}, nullptr, true);
          if (!r.failure.empty()) throw std::runtime_error("damping run: " + r.failure);
          const double e1 = model.energy(r.trajectory.states.back()).total();
          damping.add({std::string("stiff_undamped"), std::string("implicit"), dt,
                       dt * maxAngularFrequency(model, initialState(undamped)), r.count, e0, e1,
                       (e0 - e1) / dampingTime, std::log(e0 / e1) / dampingTime});
          return;
        }
        const Task& t = tasks[static_cast<std::size_t>(i)];
        const Scene& s = scenes[t.scene];
        SolverOptions options;
        const bool cvode = t.kind == IntegratorKind::Cvode;
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
      {&table, &damping});
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
        {"pose", "stretched 5% along x, at rest"}}},
      {"jobs", jobs},
      {"quick", quick},
      {"position_error_max", "max over samples and points of |x - x_ref|"},
      {"position_error_rms", "RMS over samples of the max over points of |x - x_ref|"},
      {"energy_error_max", "max over samples of |E - E_ref| / E_ref(0)"},
      {"angular_momentum_error_max", "max over samples of |L - L_ref| / max |L_ref|"},
      {"wall_time", "the steps only (set-up apart), median of the repeats; first step inside"}};
  sidecar["wall_time_s"] = since(started);
  const std::filesystem::path dir = outDir;
  if (!ranks.writeOutput("jello-work-precision", dir, name, table, sidecar,
                         {{"damping", &damping}})) {
    return 1;
  }
  if (!quiet && ranks.root()) {
    std::printf("wrote %zu + %zu rows to %s (%.1f s)\n", table.rows(), damping.rows(), dir.c_str(),
                sidecar["wall_time_s"].get<double>());
  }
  return 0;
}
