#include "integrator.h"

#include "explicit_integrators.h"

namespace jello {

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::Euler:
      return std::make_unique<ExplicitEuler>();
    case IntegratorKind::Symplectic:
      return std::make_unique<SymplecticEuler>();
    case IntegratorKind::RK4:
      return std::make_unique<RungeKutta4>();
  }
  return nullptr;
}

}  // namespace jello
