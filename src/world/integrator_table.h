// The one table of integrators. World files, jello-sim, the viewer, the Python module, the
// studies, the plots and the results scripts list, parse, print and choose integrators through
// it, and solvers/integrator_factory.cpp builds its factory from it, so an integrator added
// here is known everywhere: one row, plus its class in solvers/methods/ (src/ARCHITECTURE.md,
// "How to add an integrator"; tests/python/test_recipes.py checks that nothing else lists
// them by hand).
#pragma once

#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace jello {

// What kind of method a row is: which settings it takes (SolverOptions' structs, jello-sim's
// and the panel's groups) and whether its steps end in Newton's iterations.
enum class IntegratorFamily {
  Explicit,    // one formula per step, stable only below a step size; no solver settings
  Newton,      // implicit, solved to convergence by Newton with a line search (ImplicitOptions)
  Linearized,  // implicit, one linear solve per step (ImplicitOptions' linear solver)
  Cvode,       // SUNDIALS CVODE, error-controlled (CvodeOptions)
  Projective,  // local/global iterations on a prefactored matrix (ProjectiveOptions)
};

// How the method acts on one linear mode (frequency w, damping ratio zeta) at step h: the
// stability prediction of the explicit ones (experiments/studies/stability_analysis.h) and the
// artificial damping of the A-stable ones (experiments/studies/mode_theory.h).
enum class LinearModel {
  ForwardEuler,     // R = 1 + h lambda: stable only for h <= c/k (while zeta w_max h allows)
  SymplecticEuler,  // stable for h w_max < 2 when undamped
  RungeKutta4,      // stable for h w_max <= 2 sqrt 2 when undamped
  BackwardEuler,    // A-stable, R = 1/(1 - h lambda): damps every mode, more as h w grows
  Bdf2,             // A-stable, second order: damps high modes, low ones far less
  Trapezoidal,      // A-stable, |R| = 1 on undamped modes: no artificial damping
  Adaptive,         // error-controlled (CVODE): no threshold and no fixed damping
};

// The explicit models: stable only below a step size, which they predict.
constexpr bool hasStabilityLimit(LinearModel model) {
  return model == LinearModel::ForwardEuler || model == LinearModel::SymplecticEuler ||
         model == LinearModel::RungeKutta4;
}
// Those stable at every step on a linear system, whose artificial damping per step is theirs.
constexpr bool isAStable(LinearModel model) {
  return model == LinearModel::BackwardEuler || model == LinearModel::Bdf2 ||
         model == LinearModel::Trapezoidal;
}

// Each row: enumerator; canonical name (lowercase; accepted in any case); the spelling written
// to world files (the original course files say "Euler" and "RK4"); the class in solvers/ that
// implements it (constructed from SolverOptions); its family; its linear model; a one-line
// summary. A row without every column does not compile.
#define JELLO_INTEGRATORS(X)                                                                     \
  X(Euler, "euler", "Euler", ExplicitEuler, Explicit, ForwardEuler,                              \
    "explicit (forward) Euler, as the original")                                                 \
  X(Symplectic, "symplectic", "symplectic", SymplecticEuler, Explicit, SymplecticEuler,          \
    "semi-implicit Euler: v from the old state, then x from the new v")                          \
  X(RK4, "rk4", "RK4", RungeKutta4, Explicit, RungeKutta4, "classical fourth-order Runge-Kutta") \
  X(Implicit, "implicit", "implicit", BackwardEuler, Newton, BackwardEuler,                      \
    "backward Euler solved to convergence (Newton with line search)")                            \
  X(Cvode, "cvode", "cvode", CvodeIntegrator, Cvode, Adaptive,                                   \
    "SUNDIALS CVODE, variable-order stiff BDF")                                                  \
  X(ImplicitLinear, "implicit-linear", "implicit-linear", LinearizedBackwardEuler, Linearized,   \
    BackwardEuler, "backward Euler linearized: one linear solve per step (Baraff & Witkin)")     \
  X(Midpoint, "midpoint", "midpoint", ImplicitMidpoint, Newton, Trapezoidal,                     \
    "implicit midpoint: symplectic, second order, no artificial damping")                        \
  X(Newmark, "newmark", "newmark", Newmark, Newton, Trapezoidal,                                 \
    "average-acceleration Newmark (trapezoidal rule): second order, A-stable")                   \
  X(Bdf2, "bdf2", "bdf2", Bdf2, Newton, Bdf2,                                                    \
    "second-order BDF, started from a backward-Euler pilot")                                     \
  X(Projective, "projective", "projective", ProjectiveIntegrator, Projective, BackwardEuler,     \
    "backward Euler by prefactored local/global iterations (projective dynamics)")               \
  X(EnergyMomentum, "energy-momentum", "energy-momentum", EnergyMomentum, Newton, Trapezoidal,   \
    "discrete gradient (Gonzalez): keeps energy and momenta exactly, second order")

enum class IntegratorKind {
#define JELLO_INTEGRATOR_ENUMERATOR(kind, name, fileName, Class, family, model, summary) kind,
  JELLO_INTEGRATORS(JELLO_INTEGRATOR_ENUMERATOR)
#undef JELLO_INTEGRATOR_ENUMERATOR
};

// Case-insensitive: "RK4", "rk4", "Euler", "EULER", "symplectic" ...
std::optional<IntegratorKind> parseIntegratorName(std::string_view name);

// The canonical lowercase name ("euler", "rk4", "implicit-linear", ...).
std::string_view integratorName(IntegratorKind kind);

// The spelling the original course files use ("Euler", "RK4"); our own names otherwise.
std::string_view integratorFileName(IntegratorKind kind);

// One line saying what the integrator is, for help texts.
std::string_view integratorSummary(IntegratorKind kind);

IntegratorFamily integratorFamily(IntegratorKind kind);
LinearModel linearModel(IntegratorKind kind);
// The enumerators' names ("Newton", "BackwardEuler"): the Python module's integrator_table().
std::string_view familyName(IntegratorFamily family);
std::string_view linearModelName(LinearModel model);

// The Explicit family: a step is one explicit formula, stable only below a step size. Their
// energy may swing far above its start without growing (symplectic Euler's by up to
// 1/(1 - h w/2) near h w = 2); the others are A-stable (their LinearModel) or error-controlled
// (CVODE), so theirs has no such swing (solvers/simulation.h's divergence rule).
bool isExplicit(IntegratorKind kind);

// Every integrator, in the table's order (the viewer's number keys and every list follow it).
std::span<const IntegratorKind> allIntegrators();
// Those of the given families, in the table's order.
std::vector<IntegratorKind> integratorsOf(std::initializer_list<IntegratorFamily> families);

// "euler, symplectic, rk4, ...": every name, for help texts and error messages.
std::string integratorNameList();
// The names of the given families' integrators, in the table's order, joined by ", ".
std::string integratorNames(std::initializer_list<IntegratorFamily> families);

}  // namespace jello
