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

namespace {

using Complex = std::complex<double>;

// Spectral radius of one step of an explicit linear model with step h on
// x'' = -w^2 x - 2 zeta w x'.
double amplification(LinearModel model, double h, double w, double zeta) {
  if (model == LinearModel::SymplecticEuler) {
    // v1 = v + h(-w^2 x - 2 zeta w v), x1 = x + h v1, as a matrix on (x, v).
    Eigen::Matrix2d a;
    const double d = 1.0 - 2.0 * zeta * w * h;
    a << 1.0 - h * h * w * w, h * d, -h * w * w, d;
    return a.eigenvalues().cwiseAbs().maxCoeff();
  }
  Complex lambdas[2];
  if (zeta < 1.0) {
    const double im = w * std::sqrt(1.0 - zeta * zeta);
    lambdas[0] = {-zeta * w, im};
    lambdas[1] = {-zeta * w, -im};
  } else {
    const double s = std::sqrt(zeta * zeta - 1.0);
    lambdas[0] = -w * (zeta + s);
    lambdas[1] = -w * (zeta - s);
  }
  double worst = 0.0;
  for (const Complex& lambda : lambdas) {
    const Complex z = h * lambda;
    const Complex r = model == LinearModel::ForwardEuler
                          ? 1.0 + z
                          : 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;
    worst = std::max(worst, std::abs(r));
  }
  return worst;
}

bool stableOnAllModes(LinearModel model, double h, double wMax, double r) {
  // Modes fill (0, w_max]; 400 samples, denser toward the top, where the limit usually sits.
  for (int i = 1; i <= 400; ++i) {
    const double w = wMax * std::sqrt(i / 400.0);
    if (amplification(model, h, w, r * w / 2.0) > 1.0 + 1e-12) return false;
  }
  return true;
}

}  // namespace

double predictedThreshold(IntegratorKind kind, double wMax, double dampingRatio) {
  // Every implicit method here is A-stable on this linear test equation (its linear model:
  // backward Euler, linearized or not, and projective, which converges to it: 1/(1 - z);
  // midpoint and the trapezoidal Newmark: (1 + z/2)/(1 - z/2); BDF2), and so is cvode's BDF.
  const LinearModel model = linearModel(kind);
  if (!hasStabilityLimit(model)) return std::numeric_limits<double>::infinity();
  // Unstable already at h w_max = 1e-3 counts as never stable (forward Euler without damping
  // grows by 1 + h^2 w^2 / 2 per step at every h).
  double lo = 1e-3 / wMax, hi = 10.0 / wMax;
  if (!stableOnAllModes(model, lo, wMax, dampingRatio)) return 0.0;
  for (int i = 0; i < 200 && hi / lo > 1.0 + 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (stableOnAllModes(model, mid, wMax, dampingRatio) ? lo : hi) = mid;
  }
  return lo;
}

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
