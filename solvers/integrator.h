// The one seam between physics and time stepping: an Integrator advances a State by h using
// only the Model (forces, and later its Jacobians). makeIntegrator is the factory behind the
// name registry (integrator_name.h), so any world can be stepped by any integrator.
#pragma once

#include <memory>
#include <string>

#include "integrator_name.h"
#include "model.h"
#include "state.h"

namespace jello {

// Numerical failure is a result the caller must look at, never an exception or a silent NaN.
struct [[nodiscard]] StepResult {
  bool ok = true;
  std::string message;  // why, when !ok

  static StepResult success() { return {}; }
  static StepResult failure(std::string why) { return {false, std::move(why)}; }
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual IntegratorKind kind() const = 0;
  // Advances state.x, state.v and state.t by h seconds.
  virtual StepResult step(const Model& model, State& state, double h) = 0;
};

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind);

}  // namespace jello
