// implicit-linear: backward Euler linearized (Baraff & Witkin 1998), K = df/dx and D = df/dv
// at (x0, v0):
//   (M - h D - h^2 K) dv = h (f0 + h K v0),   v1 = v0 + dv,   x1 = x0 + h v1.
// This is the first Newton iteration of backward Euler, kept so the cost and the error of
// linearization can be measured against the converged step (`implicit`,
// solvers/methods/newton_integrators.h). On a linear system it is exact: it never blows up there
// and an undamped mode keeps 1/(1 + h^2 w^2) of its energy per step. On a stretched, spinning cube
// it is not: the transverse stiffness k (1 - L0/l) of stretched springs pins the rotation when h^2
// k (1 - L0/l)/m >> 1 (src/PHYSICS.md). A step in which a contact begins (a point reaches a wall,
// the plane or the sphere that it was clear of at the step's start) is Newton-iterated too (up to
// contactNewtonIterations): the linearized step does not know the penalty spring, lets the point in
// deep, and stores a large spurious contact energy (measured: 700x the total energy for a cube
// thrown at 20 m/s into a wall with kCollision = 10^5 at h = 0.01). The Newton iterations drive the
// residual
//   g(v1) = M (v1 - v0) - h f(x0 + h v1, v1)
// below contactNewtonTolerance relative to |M (v1 - v0)| + |h f|.
// The force field is treated explicitly (its gradient is not symmetric). With barrier contact
// a move h v1 that would carry a point into a solid is cut to 0.9 of the largest that keeps
// every point out (v1 scaled, counted in barrier_cuts): then the step is not backward Euler's.
#pragma once

#include <memory>

#include "solvers/integrator.h"
#include "solvers/system/implicit_system.h"

namespace jello {

class LinearizedBackwardEuler final : public Integrator {
 public:
  explicit LinearizedBackwardEuler(ImplicitOptions options = {});
  explicit LinearizedBackwardEuler(const SolverOptions& options)
      : LinearizedBackwardEuler(options.implicit) {}

  IntegratorKind kind() const override { return IntegratorKind::ImplicitLinear; }
  StepResult step(const Model& model, State& state, double h) override;
  std::vector<Statistic> statistics() const override;

  // Relative residual after the last step's final Newton iteration (0 for one iteration).
  double lastResidual() const { return lastResidual_; }
  int lastIterations() const { return lastIterations_; }
  const SpdSolver& linearSolver() const { return system_.solver(); }
  long clampCount() const { return system_.clampCount(); }

 private:
  void prepare(const Model& model);
  double residual(const Model& model, const State& s, double h);
  // x1 = x0 + h v1, with v1 first cut by the barrier's bound (see above).
  void keepOutside(const Model& model, const State& s, double h);
  // Factors M - h D - h^2 K of the last assembly and solves it for rhs into x (x on entry:
  // CG's initial guess).
  StepResult factorAndSolve(double h, const Eigen::VectorXd& rhs, Eigen::VectorXd& x);

  ImplicitOptions options_;
  ImplicitSystem system_;
  Eigen::VectorXd f_, rhs_, dv_, delta_, v1_, x1_, g_,
      move_;  // dv_: the last step's, CG's warm start
  double lastResidual_ = 0.0;
  int lastIterations_ = 0;
  long steps_ = 0, newtonIterations_ = 0, unconverged_ = 0, contactSteps_ = 0, barrierCuts_ = 0;
};

}  // namespace jello
