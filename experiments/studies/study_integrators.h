// Which integrators each study runs, read from the integrator table (src/world/integrator_table.h)
// and its traits, so a new row joins every study's full grid without a change here. The few
// integrators named below are picks, each with its reason: the quick grids' representatives
// (ctest's experiments label asserts on them), and the two implicit methods whose linear
// solvers the scaling study compares.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "src/world/integrator_table.h"

namespace jello::experiments {

// Error-controlled (CVODE): its axis is a tolerance, not a step.
inline bool isAdaptive(IntegratorKind kind) {
  return linearModel(kind) == LinearModel::Adaptive;
}

// Every integrator in the table's order, the adaptive ones last (their rows carry a tolerance).
std::vector<IntegratorKind> studyOrder();

// Every integrator with a step to hold fixed (all but the adaptive ones), in the table's order.
std::vector<IntegratorKind> fixedStepIntegrators();

// The first integrator of each A-stable linear model, in the models' order (backward Euler,
// BDF2, trapezoidal): the artificial damping the modal theory predicts (mode_theory.h).
std::vector<IntegratorKind> dampingRepresentatives();

// The integrators a study's --integrators option names, each an integrator's name or a family's
// ("explicit", "newton", "linearized", "cvode", "projective": its integrators in the table's
// order), none twice; `all` when none is named. The unknown name when one is.
std::variant<std::vector<IntegratorKind>, std::string> namedIntegrators(
    const std::vector<std::string>& names, const std::vector<IntegratorKind>& all);
// "integrator names, or the families explicit, newton, ...": for the option's help and error.
std::string namedIntegratorsHelp();

// The quick grids' picks. The atlas: the two explicit methods with a limit, Newton's first- and
// second-order steps and projective (experiments_test asserts on each). The drift: the same
// without projective (its energy follows implicit's). Work-precision: implicit alone among
// the implicit ones (the order test reads it).
std::vector<IntegratorKind> quickAtlasIntegrators();
std::vector<IntegratorKind> quickDriftIntegrators();
inline constexpr IntegratorKind kQuickImplicit = IntegratorKind::Implicit;

// The implicit methods whose linear solvers (CHOLMOD against CG) the scaling study compares:
// backward Euler by Newton and CVODE's BDF.
std::vector<IntegratorKind> scalingImplicitIntegrators();

}  // namespace jello::experiments
