#include "solvers/system/modes.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>

#include "solvers/system/jacobian.h"

namespace jello {

namespace {

using Complex = std::complex<double>;

// Spectral radius of one step of an explicit linear model with step h on
// x'' = -w^2 x - 2 zeta w x'.
double amplification(LinearModel model, double h, double w, double zeta) {
  if (model == LinearModel::SymplecticEuler) {
    // v1 = v + h(-w^2 x - 2 zeta w v), x1 = x + h v1, as a matrix on (x, v).
    // Its eigenvalues, the roots of l^2 - trace l + det (det = d), in closed form: Eigen's
    // general eigensolver was half of this file's compile time.
    const double d = 1.0 - 2.0 * zeta * w * h;
    const double half = (2.0 - h * h * w * w - 2.0 * zeta * w * h) / 2.0;
    const Complex root = std::sqrt(Complex(half * half - d));
    return std::max(std::abs(half + root), std::abs(half - root));
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

double maxAngularFrequency(const Model& model, const State& state) {
  return fastestMode(model, state).wMax;
}

FastestMode fastestMode(const Model& model, const State& state) {
  JacobianAssembler jacobian(model);
  jacobian.assemble(state.x.data(), {.clampCompression = false});
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
  return {std::sqrt(top), eigs.eigenvectors().col(0)};
}

std::optional<CvodeCostEstimate> cvodeCostWarning(const Model& model, const State& state,
                                                  double simulated, double kElastic,
                                                  double dElastic) {
  const Energy e = model.energy(state);
  if (!(e.kinetic + e.spring > 0.0)) return std::nullopt;  // at rest: nothing to follow
  CvodeCostEstimate c;
  try {
    c.wMax = maxAngularFrequency(model, state);
  } catch (const std::exception&) {
    return std::nullopt;  // no estimate, no warning
  }
  c.dampingRatio = kElastic > 0.0 ? dElastic * c.wMax / (2.0 * kElastic) : 1.0;
  c.steps = simulated * c.wMax / kCvodeStepTimesWmax;
  if (c.dampingRatio >= 1.0 || !(c.steps > kCvodeStepsWorthAWarning)) return std::nullopt;
  return c;
}

}  // namespace jello
