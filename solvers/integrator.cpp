#include "integrator.h"

#include "backward_euler.h"
#include "cvode_integrator.h"
#include "explicit_integrators.h"

namespace jello {

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const SolverOptions& options) {
  switch (kind) {
    case IntegratorKind::Euler:
      return std::make_unique<ExplicitEuler>();
    case IntegratorKind::Symplectic:
      return std::make_unique<SymplecticEuler>();
    case IntegratorKind::RK4:
      return std::make_unique<RungeKutta4>();
    case IntegratorKind::Implicit:
      return std::make_unique<BackwardEuler>(options.implicit);
    case IntegratorKind::Cvode:
      return std::make_unique<CvodeIntegrator>(options.cvode);
  }
  return nullptr;
}

}  // namespace jello
