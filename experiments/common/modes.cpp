#include "experiments/common/modes.h"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymEigsSolver.h>

#include <cmath>
#include <stdexcept>

#include "solvers/system/jacobian.h"

namespace jello {

double maxAngularFrequency(const Model& model, const State& state) {
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
  return std::sqrt(top);
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
