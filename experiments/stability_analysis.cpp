#include "stability_analysis.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "contact.h"
#include "jacobian.h"
#include "scene_builder.h"
#include "simulation.h"

namespace jello::experiments {

double maxAngularFrequency(const Model& model, const State& state) {
  JacobianAssembler jacobian(model);
  jacobian.assemble(state.x.data(), state.v.data(), {.clampCompression = false});
  const SparseMatrix stiffness = -jacobian.K() / model.mass();
  Spectra::SparseSymMatProd<double> op(stiffness);
  // Spectra wants ncv > nev; 20 Lanczos vectors converge the top eigenvalue in a few restarts.
  Spectra::SymEigsSolver<Spectra::SparseSymMatProd<double>> eigs(op, 1, 20);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-10);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw std::runtime_error("Spectra: the largest eigenvalue of -K/m did not converge");
  }
  const double top = eigs.eigenvalues()[0];
  if (!(top > 0.0)) throw std::runtime_error("Spectra: -K/m has no positive eigenvalue");
  return std::sqrt(top);
}

namespace {

using Complex = std::complex<double>;

// Spectral radius of one step of `kind` with step h on x'' = -w^2 x - 2 zeta w x'.
double amplification(IntegratorKind kind, double h, double w, double zeta) {
  if (kind == IntegratorKind::Symplectic) {
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
    const Complex r = kind == IntegratorKind::Euler
                          ? 1.0 + z
                          : 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;
    worst = std::max(worst, std::abs(r));
  }
  return worst;
}

bool stableOnAllModes(IntegratorKind kind, double h, double wMax, double r) {
  // Modes fill (0, w_max]; 400 samples, denser toward the top, where the limit usually sits.
  for (int i = 1; i <= 400; ++i) {
    const double w = wMax * std::sqrt(i / 400.0);
    if (amplification(kind, h, w, r * w / 2.0) > 1.0 + 1e-12) return false;
  }
  return true;
}

}  // namespace

double predictedThreshold(IntegratorKind kind, double wMax, double dampingRatio) {
  if (kind == IntegratorKind::Implicit || kind == IntegratorKind::Cvode) {
    return std::numeric_limits<double>::infinity();
  }
  // Unstable already at h w_max = 1e-3 counts as never stable (forward Euler without damping
  // grows by 1 + h^2 w^2 / 2 per step at every h).
  double lo = 1e-3 / wMax, hi = 10.0 / wMax;
  if (!stableOnAllModes(kind, lo, wMax, dampingRatio)) return 0.0;
  for (int i = 0; i < 200 && hi / lo > 1.0 + 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (stableOnAllModes(kind, mid, wMax, dampingRatio) ? lo : hi) = mid;
  }
  return lo;
}

World stabilityScene(std::string_view scene, double k, double dampingRatio, double contactRatio) {
  SceneSpec spec = stiffCube(k);
  spec.dElastic = dampingRatio * k;
  spec.pose = PosePreset::SkewedCorner;
  double shiftZ = -0.5;  // free: centred in the box, the walls 1.5 m away
  if (scene == "wall") {
    spec.kCollision = contactRatio * k;
    spec.dCollision = dampingRatio * spec.kCollision;
    spec.field = FieldPreset::Gravity;
    spec.fieldStrength = defaultFieldStrength(FieldPreset::Gravity, spec.mass);
    spec.fieldResolution = 2;  // uniform: applied as a constant force
    // A bottom point carries its column of n points: its contact spring is compressed by
    // n m g / kc at rest.
    const double load = spec.cubeResolution * spec.fieldStrength / spec.kCollision;
    shiftZ = -kBoxHalfSize - load;
  } else if (scene != "free") {
    throw std::invalid_argument("unknown scene '" + std::string(scene) + "' (free, wall)");
  }
  World w = buildWorld(spec);
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, shiftZ};
  return w;
}

Trial runTrial(const World& world, IntegratorKind kind, double dt, const BlowUpRule& rule,
               const SolverOptions& options) {
  Simulation sim(world, kind, dt, options);
  const double e0 = sim.model().energy(sim.state()).total();
  const double limit = rule.energyFactor * std::max(e0, 1e-12);
  const long steps = std::max(1L, std::lround(rule.time / dt));
  Trial trial;
  for (long i = 0; i < steps; ++i) {
    ++trial.steps;
    if (StepResult r = sim.step(); !r.ok) {
      trial.blewUp = true;
      trial.reason = r.message;
      return trial;
    }
    if ((i & 3) == 3 || i + 1 == steps) {
      const double e = sim.model().energy(sim.state()).total();
      if (!(e <= limit)) {
        trial.blewUp = true;
        trial.reason = "energy rose from " + std::to_string(e0) + " J to " + std::to_string(e) +
                       " J at t = " + std::to_string(sim.state().t) + " s";
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
