// The one registry of integrator names. World files, jello-sim, the viewer and the experiments
// all parse and print names through it, so a name accepted in one place is accepted everywhere.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace jello {

enum class IntegratorKind {
  Euler,       // explicit (forward) Euler, as the original assignment
  Symplectic,  // semi-implicit Euler: v from the old state, then x from the new v
  RK4,         // classical fourth-order Runge-Kutta
  Implicit,    // backward Euler through the sparse spring Jacobian (Baraff & Witkin)
  Cvode,       // SUNDIALS CVODE, variable-order stiff BDF
};

// Case-insensitive: "RK4", "rk4", "Euler", "EULER", "symplectic" ...
std::optional<IntegratorKind> parseIntegratorName(std::string_view name);

// The canonical lowercase name ("euler", "symplectic", "rk4", "implicit", "cvode").
std::string_view integratorName(IntegratorKind kind);

// The spelling the original course files use ("Euler", "RK4"); our own names otherwise.
std::string_view integratorFileName(IntegratorKind kind);

std::span<const IntegratorKind> allIntegrators();

// "euler, symplectic, rk4, implicit, cvode": for help texts and error messages.
std::string integratorNameList();

}  // namespace jello
