// The factory behind the integrator table (src/world/integrator_table.h): each row names the
// class that implements it, constructed from the solver options. The one file of the face that
// knows every implementation.
#pragma once

#include <memory>

#include "solvers/integrator.h"

namespace jello {

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const SolverOptions& options = {});

}  // namespace jello
