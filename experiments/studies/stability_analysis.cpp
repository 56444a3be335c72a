#include "experiments/studies/stability_analysis.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <cstdint>
#include <stdexcept>

#include "solvers/simulation.h"
#include "solvers/system/jacobian.h"
#include "src/effects/contact.h"
#include "src/world/integrator_table.h"
#include "src/world/scene_builder.h"

namespace jello::experiments {

World spinningStiffCube(double k, double damping, double spin) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = damping;
  spec.spin = spin;
  World w = buildWorld(spec);
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};
  return w;
}

World stabilityScene(std::string_view scene, double k, double dampingRatio, double contactRatio) {
  SceneSpec spec = stiffCube(k);
  spec.dElastic = dampingRatio * k;
  if (scene == "free") {
    World w = buildWorld(spec);  // the far corner pulled out by one spacing
    for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};  // centred: walls 1.5 m away
    return w;
  }
  if (scene != "wall") {
    throw std::invalid_argument("unknown scene '" + std::string(scene) + "' (free, wall)");
  }
  spec.pose = PosePreset::Rest;
  spec.kCollision = contactRatio * k;
  spec.dCollision = dampingRatio * spec.kCollision;
  // Pressed onto the floor by a uniform load scaled with the stiffness, so that a bottom point,
  // carrying its column of n points, sinks 1% of a spacing into the floor at every k: penalty
  // contact under plain gravity sinks nanometres at k = 10^6, and any vibration would lift
  // the cube off the floor it is meant to test.
  const int n = spec.cubeResolution;
  const double spacing = 1.0 / (n - 1), depth = 1e-2 * spacing;
  spec.field = FieldPreset::Gravity;
  spec.fieldStrength = depth * spec.kCollision / n;  // N per point
  spec.fieldResolution = 2;                          // uniform: applied as a constant force
  World w = buildWorld(spec);
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -kBoxHalfSize - depth / n};
  // Settled first: backward Euler at a large step damps every mode, so the run starts at the
  // loaded equilibrium. Started undeformed, the cube would settle during the run, and each
  // method's O(h) error in the energy it exchanges with the load would pass for a blow-up.
  Simulation settle(w, IntegratorKind::Implicit, 0.05);
  for (int i = 0; i < 60; ++i) {
    if (StepResult r = settle.step(); !r.ok) {
      throw std::runtime_error("wall scene did not settle: " + r.message);
    }
  }
  w = settle.currentWorld();
  w.integrator = spec.integrator;
  w.dt = spec.dt;
  // Then every point is moved by up to 10^-4 of a spacing (a fixed pseudo-random pattern) to
  // excite every mode, and starts at rest.
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  const auto next = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 11) / double(1ull << 53) * 2.0 - 1.0;
  };
  const double amplitude = 1e-4 * spacing;
  for (Vec3& p : w.positions) p += Vec3{amplitude * next(), amplitude * next(), amplitude * next()};
  for (Vec3& v : w.velocities) v = {};
  return w;
}

Trial runTrial(const World& world, IntegratorKind kind, double dt, const BlowUpRule& rule,
               const SolverOptions& options) {
  Simulation sim(world, kind, dt, options);
  const double e0 = sim.model().energy(sim.state()).total();
  double envelope = std::max(e0, 1e-12);
  const bool explicitMethod = isExplicit(kind);
  const long steps = std::max(explicitMethod ? rule.minSteps : 1L, std::lround(rule.time / dt));
  Trial trial;
  for (long i = 0; i < steps; ++i) {
    ++trial.steps;
    if (StepResult r = sim.step(); !r.ok) {
      trial.blewUp = true;
      trial.reason = r.message;
      return trial;
    }
    const bool inEnvelope = explicitMethod && i < kBlowUpEnvelopeSteps;  // implicit: the start
    if (i < kBlowUpEnvelopeSteps || (i & 3) == 3 || i + 1 == steps) {
      // Net of the work the force field (the wall scene's load) has done, as the simulation
      // counts it.
      const double e = sim.model().energy(sim.state()).total() - sim.fieldWork();
      if (inEnvelope && e == e) {
        envelope = std::max(envelope, e);
      } else if (!(e <= rule.energyFactor * envelope)) {
        trial.blewUp = true;
        trial.reason = "energy rose from an envelope of " + std::to_string(envelope) + " J to " +
                       std::to_string(e) + " J at t = " + std::to_string(sim.state().t) + " s";
        return trial;
      }
    }
  }
  return trial;
}

Threshold findThreshold(const World& world, IntegratorKind kind, const BlowUpRule& rule,
                        double guess, double dtMax, double relativeTolerance, double dtMin,
                        const SolverOptions& options) {
  Threshold t;
  const auto stable = [&](double dt) {
    ++t.trials;
    return !runTrial(world, kind, dt, rule, options).blewUp;
  };
  if (stable(dtMax)) {
    t.stable = dtMax;
    return t;
  }
  t.unstable = dtMax;
  double dt = std::min(guess, dtMax / 2.0);
  // Bracket: walk down until stable, or up (below dtMax) while stable.
  while (true) {
    if (dt < dtMin) return t;  // unstable all the way down: stable stays 0
    if (stable(dt)) {
      t.stable = dt;
      break;
    }
    t.unstable = dt;
    dt /= 2.0;
  }
  for (double up = t.stable * 2.0; up < t.unstable; up *= 2.0) {
    if (!stable(up)) {
      t.unstable = up;
      break;
    }
    t.stable = up;
  }
  while (t.unstable / t.stable > 1.0 + relativeTolerance) {
    const double mid = std::sqrt(t.stable * t.unstable);
    (stable(mid) ? t.stable : t.unstable) = mid;
  }
  return t;
}

}  // namespace jello::experiments
