// jello-sim: steps a world headless and reports what happened.
//   jello-sim WORLD [--integrator NAME] [--dt S] [--time S | --steps N] [--cube N]
//             [--out FILE.w] [--trace FILE.csv --every K] [--stats FILE.json] [--quiet] [--strict]
// Exit codes: 0 done, 1 bad input, an I/O failure or a step that cannot run here (a memory limit),
// 2 bad usage, 3 the simulation diverged, 4 a step left unconverged under --strict,
// 128 + signal when interrupted by SIGINT, SIGTERM or SIGHUP (it stops at a step boundary).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "experiments/common/progress.h"
#include "experiments/common/signal_handler.h"
#include "experiments/tools/contact_flags.h"
#include "experiments/tools/output_check.h"
#include "experiments/tools/sim_report.h"
#include "experiments/tools/solver_flags.h"
#include "solvers/linalg/solver_threads.h"
#include "solvers/simulation.h"
#include "solvers/system/modes.h"
#include "src/base/finite_options.h"
#include "src/base/interrupt.h"
#include "src/base/out_of_memory.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"

namespace {

using jello::Energy;
using jello::Simulation;
using jello::simtool::Options;
using jello::simtool::Outcome;
using jello::simtool::Trace;

constexpr int kExitInput = 1;
constexpr int kExitUsage = 2;
constexpr int kExitDiverged = 3;
constexpr int kExitUnconverged = 4;

volatile std::sig_atomic_t interruptSignal = 0;

extern "C" void onInterrupt(int signo) {
  interruptSignal = signo;
  jello::requestInterrupt(signo);  // polled inside long steps too (src/base/interrupt.h)
}

void warnOfLightlyDampedStiffness(const Simulation& sim, double simulated, double kElastic,
                                  double dElastic) {
  const auto w = jello::cvodeCostWarning(sim.model(), sim.state(), simulated, kElastic, dElastic);
  if (!w) return;
  std::fprintf(
      stderr,
      "jello-sim: warning: cvode follows this scene's fastest mode (w_max = %.3g rad/s, "
      "damping ratio %.2g) at its tolerance: if the start excites it, expect about %.2g "
      "internal steps for %g simulated s (h w_max ~ %g, measured). implicit or "
      "projective at --dt 0.001 step over it, at the price of damping it (solvers/README.md, "
      "\"cvode on very stiff scenes\")\n",
      w->wMax, w->dampingRatio, w->steps, simulated, jello::kCvodeStepTimesWmax);
}

// The world of the command line, its integrator overridable; nothing after an error (said).
std::optional<jello::World> loadWorld(const Options& opt) {
  jello::World world;
  try {
    jello::ReaderLimits limits = opt.limits;
    limits.acceptUnknownIntegrator = !opt.integrator.empty();  // --integrator overrides it
    world = jello::readWorld(opt.world, limits);
  } catch (const jello::WorldFileError& e) {
    std::fprintf(stderr, "jello-sim: error: %s\n", e.what());
    return std::nullopt;
  }
  if (!world.unknownIntegrator.empty()) {
    std::fprintf(stderr,
                 "jello-sim: warning: %s names the integrator '%s', unknown here; stepping "
                 "with --integrator %s\n",
                 opt.world.c_str(), world.unknownIntegrator.c_str(), opt.integrator.c_str());
  }
  if (opt.cube) world = jello::resampleCube(world, *opt.cube);
  return world;
}

// The steps --time or --steps ask for, or nothing (said) when there are too many. A --time that
// is not a whole number of steps ends past it, never short of it: a note says by how much.
std::optional<long> stepCount(const Options& opt, const Simulation& sim) {
  const double dt = sim.dt();
  const double wanted =
      opt.steps ? double(*opt.steps) : std::ceil(opt.time.value_or(1.0) / dt - 1e-9);
  if (!(wanted <= 1e12)) {  // also catches an overflowing quotient before the cast to long
    std::fprintf(stderr, "jello-sim: error: %.3g steps asked for; at most 1e12 per run\n", wanted);
    return std::nullopt;
  }
  const long total = static_cast<long>(wanted);
  if (!opt.steps && opt.time && !opt.quiet) {
    const double end = sim.state().t + double(total) * dt, asked = sim.state().t + *opt.time;
    if (std::abs(end - asked) > 1e-9 * std::max(1.0, std::abs(asked))) {
      std::fprintf(stderr,
                   "jello-sim: note: --time %g s is not a whole number of steps of %g s: running "
                   "%ld steps, to t = %.9g s (%.3g s past)\n",
                   *opt.time, dt, total, end, end - asked);
    }
  }
  return total;
}

// Steps until `total`, a divergence, a failure or a signal (SIGINT, SIGTERM and SIGHUP stop at
// a step boundary; the stats and the trace are written), tracing every opt.every steps.
void stepAll(Simulation& sim, const Options& opt, Trace& trace, Outcome& o) {
  const std::string name(jello::integratorName(sim.integratorKind()));
  trace.row(sim);
  jello::Progress progress(!opt.quiet, name + " steps");
  const auto t0 = std::chrono::steady_clock::now();
  for (int signo : {SIGINT, SIGTERM, SIGHUP})
    jello::setSignalHandler("jello-sim", signo, onInterrupt);
  for (long i = 0; i < o.total && interruptSignal == 0; ++i) {
    if (const jello::StepResult r = sim.step(); !r.ok) {
      if (r.resource) o.failure = r.message;
      o.diverged = !r.interrupted && !r.resource;  // both leave the state at the step's start
      break;
    } else if (r.unconverged && opt.strict) {
      std::ostringstream os;
      os << "step " << sim.steps() << " (to t = " << sim.state().t << " s, integrator " << name
         << ") did not converge within ";
      if (sim.integratorKind() == jello::IntegratorKind::ImplicitLinear) {
        os << opt.solver.implicit.contactNewtonIterations
           << " Newton iterations at a contact onset (--strict)";
      } else {
        os << opt.solver.implicit.newtonMaxIterations << " Newton iterations, even as "
           << (1 << opt.solver.implicit.newtonHalvings) << " sub-steps (--strict)";
      }
      o.unconverged = os.str();
      break;
    }
    if (sim.steps() % opt.every == 0) trace.row(sim);
    progress.update(i + 1, o.total);
  }
  // The last state faces the energy rule too (it checks every few steps): a run never ends
  // with exit 0 on a state the rule would flag a step later.
  if (!o.diverged && o.failure.empty() && o.unconverged.empty() && interruptSignal == 0 &&
      !sim.checkEnergy().ok) {
    o.diverged = true;
  }
  o.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (int signo : {SIGINT, SIGTERM, SIGHUP}) jello::setSignalHandler("jello-sim", signo, SIG_DFL);
  o.interrupted = interruptSignal;
  progress.finish();
  o.done = o.diverged ? sim.steps() - 1 : sim.steps();  // an unconverged step was taken
  o.end = sim.model().energy(sim.state());
  o.endL = sim.model().angularMomentum(sim.state());
}

int run(const Options& opt) {
  // Every output is checked before the run: an I/O failure (exit 1) or two outputs naming one
  // file (exit 2), found before it starts.
  std::vector<jello::PlannedOutput> outputs;
  if (opt.outGiven) outputs.push_back({"--out", opt.out});
  if (opt.statsGiven) outputs.push_back({"--stats", opt.stats});
  if (opt.traceGiven) outputs.push_back({"--trace", opt.trace});
  switch (jello::checkOutputs("jello-sim", outputs)) {
    case jello::OutputCheck::Ok:
      break;
    case jello::OutputCheck::Unwritable:
      return kExitInput;
    case jello::OutputCheck::SameFile:
      return kExitUsage;
  }
  std::optional<jello::World> world = loadWorld(opt);
  if (!world) return kExitInput;
  if (std::string error = jello::applyContactFlags(opt.contact, world->contact, world->kCollision);
      !error.empty()) {
    std::fprintf(stderr, "jello-sim: error: %s\n", error.c_str());
    return kExitUsage;
  }
  std::optional<jello::IntegratorKind> kind;
  if (!opt.integrator.empty()) {
    kind = jello::parseIntegratorName(opt.integrator);
    if (!kind) {
      std::fprintf(stderr, "jello-sim: error: unknown integrator '%s' (known: %s)\n",
                   opt.integrator.c_str(), jello::integratorNameList().c_str());
      return kExitUsage;
    }
  }
  const double kElastic = world->kElastic, dElastic = world->dElastic;
  Simulation sim(std::move(*world), kind, opt.dt, opt.solver);
  if (const std::optional<jello::StartProblem> why = sim.model().startProblem(sim.state())) {
    std::fprintf(stderr, "jello-sim: error: %s\n",
                 jello::startError(*why, sim.world(), opt.world).what());
    return kExitInput;
  }
  sim.trackObstacleDistance();
  Outcome o;
  if (const std::optional<long> total = stepCount(opt, sim)) {
    o.total = *total;
  } else {
    return kExitUsage;
  }
  if (jello::integratorFamily(sim.integratorKind()) == jello::IntegratorFamily::Cvode &&
      !opt.quiet) {
    warnOfLightlyDampedStiffness(
        sim, opt.steps ? double(o.total) * sim.dt() : opt.time.value_or(1.0), kElastic, dElastic);
  }
  o.start = sim.model().energy(sim.state());
  o.startL = sim.model().angularMomentum(sim.state());
  Trace trace(!opt.trace.empty());
  stepAll(sim, opt, trace, o);
  const nlohmann::json stats = statistics(opt, sim, o);
  if (!opt.quiet) printSummary(opt, sim, o);
  if (!writeOutputs(opt, sim, o, trace, stats)) return kExitInput;
  if (!o.failure.empty()) return kExitInput;
  if (o.interrupted) return 128 + o.interrupted;
  if (!o.unconverged.empty()) return kExitUnconverged;
  return o.diverged ? kExitDiverged : 0;
}

// The command line into opt; an exit code when the program stops here (--help, bad usage).
std::optional<int> parseCommandLine(int argc, char** argv, Options& opt) {
  CLI::App app{
      "Steps a jello world headless and prints a summary: steps, simulated and wall time, "
      "steps/s, real-time factor, energy at start and end, and the solver's statistics. For "
      "cvode, --dt is the output interval; CVODE chooses its own internal steps.\n"
      "Exit codes: 0 done, 1 bad world file, I/O failure or a memory limit too tight, 2 bad usage, "
      "3 diverged, 4 a step left unconverged with --strict, "
      "128+N interrupted by signal N (Ctrl-C: 130; trace and stats are written, --out is not).",
      "jello-sim"};
  app.add_option("world", opt.world, "World file (.w)")->required();
  app.add_option("--integrator", opt.integrator,
                 "Integrator, overriding the file's: " + jello::integratorNameList());
  app.add_option("--dt", opt.dt, "Time step in seconds, overriding the file's")
      ->check(jello::cli::positive());
  jello::addContactFlags(app, opt.contact, "overriding the file's");
  auto* time = app.add_option("--time", opt.time, "Simulated time to run, s (default 1)")
                   ->check(jello::cli::positive());
  app.add_option("--steps", opt.steps, "Number of steps to run instead of --time")
      ->check(jello::cli::nonNegative())
      ->excludes(time);
  app.add_option("--cube", opt.cube, "Resample the cube to N^3 points (initial state interpolated)")
      ->check(jello::cli::range(2, 64));
  app.add_option("--out", opt.out, "Write the final state as a world file");
  auto* trace = app.add_option("--trace", opt.trace, "Write energies and centre of mass (CSV)");
  app.add_option("--every", opt.every, "Trace every K steps (default 100)")
      ->check(jello::cli::positive())
      ->needs(trace);
  app.add_option("--stats", opt.stats, "Write the summary as JSON");
  app.add_flag("--quiet,-q", opt.quiet, "Print nothing but errors");
  app.add_flag("--strict", opt.strict,
               "Stop with exit code 4 at the first step Newton leaves unconverged, even after "
               "its retries in half steps (without it, such steps are accepted, counted and "
               "reported)");
  app.add_option("--max-field-resolution", opt.limits.maxFieldResolution,
                 "Refuse worlds with a larger force field (nodes per axis)")
      ->check(jello::cli::range(2, 1024))
      ->capture_default_str()
      ->group("Limits (checked before memory is allocated)");
  app.add_option("--max-cube-resolution", opt.limits.maxCubeResolution,
                 "Refuse worlds with a larger cube (points per axis)")
      ->check(jello::cli::range(2, 256))
      ->capture_default_str()
      ->group("Limits (checked before memory is allocated)");
  jello::SolverFlags solverFlags;
  jello::addSolverFlags(app, solverFlags);
  try {
    app.parse(argc, argv);
    jello::refuseNonFiniteNumbers(app);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : kExitUsage;
  }
  opt.solver = jello::solverOptions(solverFlags);
  opt.outGiven = app.count("--out") > 0;
  opt.statsGiven = app.count("--stats") > 0;
  opt.traceGiven = app.count("--trace") > 0;
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  jello::exitCleanlyWhenOutOfMemory("jello-sim");
  jello::ignoreBrokenPipes("jello-sim");
  jello::applySolverThreadSettings();
  // A file-size limit (or a quota) must fail the write, which is reported and cleaned up, not
  // kill the process with a temporary file left behind.
  jello::setSignalHandler("jello-sim", SIGXFSZ, SIG_IGN);
  Options opt;
  if (const std::optional<int> code = parseCommandLine(argc, argv, opt)) return *code;
  return run(opt);
}
