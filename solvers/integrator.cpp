#include "solvers/integrator.h"

#include "solvers/cvode_integrator.h"
#include "solvers/explicit_integrators.h"
#include "solvers/linearized_backward_euler.h"
#include "solvers/newton_integrators.h"
#include "solvers/projective_integrator.h"

namespace jello {

std::optional<double> findStatistic(const std::vector<Statistic>& statistics,
                                    std::string_view name) {
  for (const Statistic& s : statistics) {
    if (s.name == name) return s.value;
  }
  return std::nullopt;
}

// Built from the one table of integrators (src/integrator_name.h): each row names its class.
std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const SolverOptions& options) {
  switch (kind) {
#define JELLO_MAKE_INTEGRATOR(kind, name, fileName, Class, summary) \
  case IntegratorKind::kind:                                        \
    return std::make_unique<Class>(options);
    JELLO_INTEGRATORS(JELLO_MAKE_INTEGRATOR)
#undef JELLO_MAKE_INTEGRATOR
  }
  return nullptr;
}

}  // namespace jello
