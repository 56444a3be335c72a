#include "experiments/tools/sim_report.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "experiments/common/json_finite.h"
#include "src/base/atomic_file.h"
#include "src/world/world_writer.h"

namespace jello::simtool {

namespace {

nlohmann::json toJson(const Energy& e) {
  return {{"kinetic_J", e.kinetic},
          {"spring_J", e.spring},
          {"contact_J", e.contact},
          {"total_J", e.total()}};
}

// On standard error: `count` steps were accepted unconverged, and what to do about it.
void warnUnconverged(const Options& opt, const Simulation& sim, double count) {
  // An unconverged step that then diverged is not in sim.steps(): "1 of 0 steps" said so.
  const long taken = std::max(sim.steps(), static_cast<long>(count));
  if (sim.integratorKind() == IntegratorKind::ImplicitLinear) {
    // Its Newton runs only where contact begins, to a cap of its own: the Newton options do
    // nothing for it.
    std::fprintf(stderr,
                 "jello-sim: warning: %.0f of %ld steps taken were accepted unconverged: at a "
                 "contact onset implicit-linear iterates at most %d times to a residual of %g, "
                 "then keeps its step (--strict makes this an error; the converged method: "
                 "--integrator implicit; a contact whose force has no jump: --contact smooth; "
                 "solvers/README.md, \"implicit-linear\")\n",
                 count, taken, opt.solver.implicit.contactNewtonIterations,
                 opt.solver.implicit.contactNewtonTolerance);
    return;
  }
  const int halvings = opt.solver.implicit.newtonHalvings;
  const std::string retried =
      halvings > 0 ? ", even in sub-steps of 1/" + std::to_string(1 << halvings) : "";
  std::fprintf(stderr,
               "jello-sim: warning: %.0f of %ld steps taken were accepted unconverged: Newton "
               "did not converge within %d iterations (more while its residual still fell)%s "
               "(raise --newton-iters or "
               "--newton-halvings; --strict makes this an error; where a point meets a wall "
               "at speed the penalty's damping force jumps and the step's equations may have "
               "no root: --contact smooth; solvers/README.md, \"implicit\")\n",
               count, taken, opt.solver.implicit.newtonMaxIterations, retried.c_str());
}

}  // namespace

Trace::Trace(bool on) : on_(on) {
  if (on_) csv_ << "step,t_s,kinetic_J,spring_J,contact_J,total_J,com_x_m,com_y_m,com_z_m\n";
}

void Trace::row(const Simulation& sim) {
  if (!on_) return;
  const State& s = sim.state();
  const Energy e = sim.model().energy(s);
  const Vec3 com = s.centroid();
  char buf[320];
  std::snprintf(buf, sizeof buf, "%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                sim.steps(), s.t, e.kinetic, e.spring, e.contact, e.total(), com.x, com.y, com.z);
  csv_ << buf;
}

// The summary as JSON (--stats), and on stderr what went wrong: unconverged steps, a signal, a
// failure, a divergence.
nlohmann::json statistics(const Options& opt, const Simulation& sim, const Outcome& o) {
  const State& s = sim.state();
  nlohmann::json stats = {
      {"world", opt.world},
      {"integrator", std::string(integratorName(sim.integratorKind()))},
      {"dt_s", sim.dt()},
      {"contact",
       {{"model", std::string(contactModelName(sim.world().contact.model))},
        {"layer_m", sim.world().contact.layer},
        {"dhat_m", sim.world().contact.dhat},
        {"kappa_N_per_m", sim.world().contact.kappa},
        {"friction_mu", sim.world().contact.mu},
        {"slip_speed_m_per_s", sim.world().contact.slipSpeed},
        {"friction_work_J", sim.frictionWork()}}},
      {"points", s.numPoints()},
      {"springs", sim.model().springs().numSprings()},
      {"steps", o.done},
      {"simulated_time_s", s.t},
      {"wall_time_s", o.wall},
      {"steps_per_s", o.wall > 0 ? double(o.done) / o.wall : 0.0},
      {"real_time_factor", o.wall > 0 ? s.t / o.wall : 0.0},
      {"energy_start", toJson(o.start)},
      {"energy_end", toJson(o.end)},
      {"angular_momentum_start_kg_m2_per_s", {o.startL.x, o.startL.y, o.startL.z}},
      {"angular_momentum_end_kg_m2_per_s", {o.endL.x, o.endL.y, o.endL.z}},
      {"diverged", o.diverged},
      {"interrupted", o.interrupted != 0},
  };
  // The least signed distance to a solid over the run (< 0: the deepest penetration); null
  // without solids.
  if (const std::optional<double> d = sim.minObstacleDistance()) {
    stats["min_obstacle_distance_m"] = *d;
  } else {
    stats["min_obstacle_distance_m"] = nullptr;
    stats["null_because"]["min_obstacle_distance_m"] = "the scene has no solid";
  }
  for (const Statistic& st : sim.integrator().statistics()) {
    stats["solver"][st.name] = st.value;
    if (st.name == "newton_unconverged_steps" && st.value > 0 && o.unconverged.empty()) {
      warnUnconverged(opt, sim, st.value);
    }
  }
  if (o.interrupted) {
    std::fprintf(stderr, "jello-sim: interrupted (signal %d) at t = %g s, after step %ld of %ld\n",
                 o.interrupted, s.t, o.done, o.total);
  }
  if (!o.failure.empty()) {
    stats["failure"] = o.failure;
    std::fprintf(stderr, "jello-sim: error: %s\n", o.failure.c_str());
  }
  if (!o.unconverged.empty()) {
    stats["unconverged"] = o.unconverged;
    std::fprintf(stderr, "jello-sim: error: %s\n", o.unconverged.c_str());
  }
  if (o.diverged) {
    const Divergence& d = *sim.divergence();
    stats["divergence"] = {{"time_s", d.time}, {"step", d.step}, {"reason", d.reason}};
    std::fprintf(stderr, "jello-sim: %s\n", d.describe().c_str());
  }
  explainNonFinite(stats);
  return stats;
}

void printSummary(const Options& opt, const Simulation& sim, const Outcome& o) {
  const State& s = sim.state();
  const std::string name(integratorName(sim.integratorKind()));
  std::printf("world        %s (%d points, %d springs)\n", opt.world.c_str(), s.numPoints(),
              sim.model().springs().numSprings());
  std::printf("integrator   %s, dt = %g s\n", name.c_str(), sim.dt());
  std::printf("steps        %ld%s\n", o.done,
              o.diverged      ? " (then diverged)"
              : o.interrupted ? " (interrupted)"
              : !o.failure.empty() || !o.unconverged.empty()
                  ? " (then stopped: see the error above)"
                  : "");
  std::printf("simulated    %.6g s\n", s.t);
  std::printf("wall time    %.3f s (%.0f steps/s, %.2fx real time)\n", o.wall,
              o.wall > 0 ? double(o.done) / o.wall : 0.0, o.wall > 0 ? s.t / o.wall : 0.0);
  std::printf("energy (J)   %12s %12s %12s %12s\n", "kinetic", "spring", "contact", "total");
  std::printf("  start      %12.6g %12.6g %12.6g %12.6g\n", o.start.kinetic, o.start.spring,
              o.start.contact, o.start.total());
  std::printf("  %-10s %12.6g %12.6g %12.6g %12.6g\n", o.diverged ? "last sane" : "end",
              o.end.kinetic, o.end.spring, o.end.contact, o.end.total());
  for (const Statistic& st : sim.integrator().statistics()) {
    std::printf("  %-28s %.6g\n", st.name.c_str(), st.value);
  }
}

// Every output that can be written is: one failing does not lose the others. A diverged,
// interrupted or failed run saves no world (its last state is not the state at the requested
// time); its trace and stats are complete up to where it stopped, and say so. False when a
// write failed.
bool writeOutputs(const Options& opt, const Simulation& sim, const Outcome& o, const Trace& trace,
                  const nlohmann::json& stats) {
  bool writeFailed = false;
  const auto attempt = [&](auto&& write) {
    try {
      write();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "jello-sim: error: %s\n", e.what());
      writeFailed = true;
    }
  };
  const bool complete = !o.diverged && !o.interrupted && o.failure.empty() && o.unconverged.empty();
  if (!opt.trace.empty()) attempt([&] { writeFileAtomically(opt.trace, trace.text()); });
  if (!opt.stats.empty()) {
    attempt([&] { writeFileAtomically(opt.stats, stats.dump(2) + "\n"); });
  }
  if (!opt.out.empty() && complete) attempt([&] { writeWorld(sim.currentWorld(), opt.out); });
  if (writeFailed) return false;
  if (!complete && !opt.out.empty()) {
    std::fprintf(stderr, "jello-sim: %s not written (the simulation %s)\n", opt.out.c_str(),
                 o.diverged               ? "diverged"
                 : o.interrupted          ? "was interrupted"
                 : !o.unconverged.empty() ? "stopped at an unconverged step"
                                          : "could not go on");
  }
  return true;
}

}  // namespace jello::simtool
