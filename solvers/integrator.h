// The one seam between physics and time stepping: an Integrator advances a State by h using
// only the Model (forces and Jacobians). The wings implement it (solvers/methods/,
// solvers/cvode/); solvers/integrator_factory.h builds one from the integrator table
// (src/world/integrator_table.h), so any world can be stepped by any integrator.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "solvers/solver_options.h"
#include "solvers/step_result.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/integrator_table.h"

namespace jello {

// A named figure an integrator reports about its work (solver statistics, timings).
struct Statistic {
  std::string name;  // snake_case with its unit, e.g. "factor_time_s"
  double value;
};

// The value of the statistic called `name`, when `statistics` has one.
std::optional<double> findStatistic(const std::vector<Statistic>& statistics,
                                    std::string_view name);

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual IntegratorKind kind() const = 0;
  // Advances state.x, state.v and state.t by h seconds, writing into the state's vectors in
  // place: never resized, swapped or moved, so views of them (the Python module's numpy
  // arrays) stay valid.
  virtual StepResult step(const Model& model, State& state, double h) = 0;
  virtual std::vector<Statistic> statistics() const { return {}; }
  // The model's forces changed from outside (a user force was set): an integrator that carries
  // history from step to step must start afresh at the next step.
  virtual void restart() {}
};

}  // namespace jello
