// The explicit integrators, each exactly as src/PHYSICS.md states it (a = M^-1 f(x, v)):
//   euler       a from the old state; x += h v_old; v += h a              (order 1)
//   symplectic  a from the old state; v += h a;     x += h v_new          (order 1, symplectic)
//   rk4         classical four stages on (x, v)                           (order 4)
// Workspaces are allocated once, on the first step, never per step.
#pragma once

#include <Eigen/Core>

#include "solvers/integrator.h"

namespace jello {

class ExplicitEuler final : public Integrator {
 public:
  ExplicitEuler() = default;
  explicit ExplicitEuler(const SolverOptions&) {
  }  // nothing to set: the factory's uniform signature
  IntegratorKind kind() const override { return IntegratorKind::Euler; }
  StepResult step(const Model& model, State& state, double h) override;

 private:
  Eigen::VectorXd a_;
};

class SymplecticEuler final : public Integrator {
 public:
  SymplecticEuler() = default;
  explicit SymplecticEuler(const SolverOptions&) {
  }  // nothing to set: the factory's uniform signature
  IntegratorKind kind() const override { return IntegratorKind::Symplectic; }
  StepResult step(const Model& model, State& state, double h) override;

 private:
  Eigen::VectorXd a_;
};

class RungeKutta4 final : public Integrator {
 public:
  RungeKutta4() = default;
  explicit RungeKutta4(const SolverOptions&) {}  // nothing to set: the factory's uniform signature
  IntegratorKind kind() const override { return IntegratorKind::RK4; }
  StepResult step(const Model& model, State& state, double h) override;

 private:
  Eigen::VectorXd xs_, vs_;  // stage state
  Eigen::VectorXd a_;        // stage acceleration
  Eigen::VectorXd dx_, dv_;  // weighted sums of the stage slopes
};

}  // namespace jello
