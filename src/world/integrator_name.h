// The one table of integrators. World files, jello-sim, the viewer and the experiments parse
// and print names through it, and solvers/integrator.cpp builds its factory from it, so an
// integrator added here is known everywhere: one row, plus its class in solvers/
// (src/ARCHITECTURE.md, "How to add an integrator").
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace jello {

// Each row: enumerator, canonical name (lowercase; accepted in any case), the spelling written
// to world files (the original course files say "Euler" and "RK4"), the class in solvers/ that
// implements it (constructed from SolverOptions), and a one-line summary.
#define JELLO_INTEGRATORS(X)                                                              \
  X(Euler, "euler", "Euler", ExplicitEuler, "explicit (forward) Euler, as the original")  \
  X(Symplectic, "symplectic", "symplectic", SymplecticEuler,                              \
    "semi-implicit Euler: v from the old state, then x from the new v")                   \
  X(RK4, "rk4", "RK4", RungeKutta4, "classical fourth-order Runge-Kutta")                 \
  X(Implicit, "implicit", "implicit", BackwardEuler,                                      \
    "backward Euler solved to convergence (Newton with line search)")                     \
  X(Cvode, "cvode", "cvode", CvodeIntegrator, "SUNDIALS CVODE, variable-order stiff BDF") \
  X(ImplicitLinear, "implicit-linear", "implicit-linear", LinearizedBackwardEuler,        \
    "backward Euler linearized: one linear solve per step (Baraff & Witkin)")             \
  X(Midpoint, "midpoint", "midpoint", ImplicitMidpoint,                                   \
    "implicit midpoint: symplectic, second order, no artificial damping")                 \
  X(Newmark, "newmark", "newmark", Newmark,                                               \
    "average-acceleration Newmark (trapezoidal rule): second order, A-stable")            \
  X(Bdf2, "bdf2", "bdf2", Bdf2, "second-order BDF, started by backward Euler")            \
  X(Projective, "projective", "projective", ProjectiveIntegrator,                         \
    "backward Euler by prefactored local/global iterations (projective dynamics)")

enum class IntegratorKind {
#define JELLO_INTEGRATOR_ENUMERATOR(kind, name, fileName, Class, summary) kind,
  JELLO_INTEGRATORS(JELLO_INTEGRATOR_ENUMERATOR)
#undef JELLO_INTEGRATOR_ENUMERATOR
};

// Case-insensitive: "RK4", "rk4", "Euler", "EULER", "symplectic" ...
std::optional<IntegratorKind> parseIntegratorName(std::string_view name);

// The canonical lowercase name ("euler", "symplectic", "rk4", "implicit", "cvode").
std::string_view integratorName(IntegratorKind kind);

// The spelling the original course files use ("Euler", "RK4"); our own names otherwise.
std::string_view integratorFileName(IntegratorKind kind);

// One line saying what the integrator is, for help texts.
std::string_view integratorSummary(IntegratorKind kind);

// Euler, symplectic Euler and RK4: a step is one explicit formula, stable only below a step
// size. Their energy may swing far above its start without growing (symplectic Euler's by up to
// 1/(1 - h w/2) near h w = 2); the others are A-stable (backward Euler, BDF2 and projective damp
// a linear system, midpoint and Newmark keep its energy) or error-controlled (CVODE), so theirs
// has no such swing (solvers/simulation.h's divergence rule).
bool isExplicit(IntegratorKind kind);

// Every integrator, in the table's order (the viewer's number keys follow it).
std::span<const IntegratorKind> allIntegrators();

// "euler, symplectic, rk4, implicit, cvode": for help texts and error messages.
std::string integratorNameList();

}  // namespace jello
