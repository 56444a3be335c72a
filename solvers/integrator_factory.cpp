#include "solvers/integrator_factory.h"

#include "solvers/cvode/cvode_integrator.h"
#include "solvers/methods/energy_momentum.h"
#include "solvers/methods/explicit_integrators.h"
#include "solvers/methods/linearized_backward_euler.h"
#include "solvers/methods/newton_integrators.h"
#include "solvers/methods/projective_integrator.h"

namespace jello {

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const SolverOptions& options) {
  switch (kind) {
#define JELLO_MAKE_INTEGRATOR(kind, name, fileName, Class, family, model, summary) \
  case IntegratorKind::kind:                                                       \
    return std::make_unique<Class>(options);
    JELLO_INTEGRATORS(JELLO_MAKE_INTEGRATOR)
#undef JELLO_MAKE_INTEGRATOR
  }
  return nullptr;
}

}  // namespace jello
