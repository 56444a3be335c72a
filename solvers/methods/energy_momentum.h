// energy-momentum: a discrete-gradient step (Simo & Tarnow 1992; Gonzalez 1996) that keeps the
// energy of every spring and the linear and angular momentum exactly, at any step size
// (src/PHYSICS.md, "The energy-momentum step"). The step from (x0, v0) to (x1, v1):
//   x1 - x0 = h (v0 + v1)/2,   M (v1 - v0)/h = F,
// so Delta(kinetic energy) = F . (x1 - x0), with F:
//   springs   the midpoint direction d_m = (d0 + d1)/2 times the difference quotient of the
//             spring's energy U(q) = k/2 (sqrt q - L)^2 over its squared length q = |d|^2:
//             F_b = -F_a = -2 (U(q1) - U(q0))/(q1 - q0) d_m = -k (1 - 2L/(l0 + l1)) d_m,
//             so F . Delta x = -(U(l1) - U(l0)) exactly, and F is central: no torque, no net
//             force;
//   contact   the contact forces at the midpoint plus Gonzalez's correction along the step,
//             F_c(x_m) + [(-(U_c(x1) - U_c(x0)) - F_c(x_m) . Dx) / |Dx|^2] Dx, which makes their
//             work exactly minus the change of the contact energy (any model: penalty, smooth,
//             barrier); it is used only when a point touches at x0, x1 or x_m;
//   damping   spring and contact damping and friction at the midpoint and the midpoint velocity
//             v_m = (x1 - x0)/h (the model's forces at (x_m, v_m) less those at (x_m, 0)): the
//             energy falls by exactly the work h F_d . v_m <= 0 they do;
//   external  the field and the user force at x_m: their work F . Dx.
// The step's equations r(x1) = 2M/h^2 (x1 - x0 - h v0) - F(x0, x1) = 0 are solved by Newton
// from the implicit midpoint's step (its energy merit carries Newton through a start that
// crushes springs, where |r| as a merit stalls), with the springs' exact discrete-gradient
// Jacobian (not symmetric: BiCGSTAB, preconditioned by the midpoint's symmetric matrix factored
// by CHOLMOD; a sparse LU where it stalls) and the midpoint's for contact and damping
// (2M/h^2 - K/2 - D/h at x_m), and a backtracking line search on |r|. Newton stops at the relative
// residual ImplicitOptions::newtonTolerance (|r| over |2M/h^2 (x1 - x0 - h v0)| + |F|) or when an
// update moves no coordinate more than newtonPositionTolerance; at newtonMaxIterations (further
// while |r| still halves every ten iterations: solvers/methods/newton_cap.h) the step is
// retried as two half steps, down to h / 2^newtonHalvings, where it is accepted, counted and
// reported unconverged (never silently).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "solvers/integrator.h"
#include "solvers/linalg/linear_solver.h"
#include "solvers/methods/newton_integrators.h"
#include "solvers/system/jacobian.h"

namespace jello {

struct SparseLuFallback;  // energy_momentum.cpp

class EnergyMomentum final : public Integrator {
 public:
  explicit EnergyMomentum(const SolverOptions& options);
  ~EnergyMomentum() override;

  IntegratorKind kind() const override { return IntegratorKind::EnergyMomentum; }
  StepResult step(const Model& model, State& state, double h) override;
  std::vector<Statistic> statistics() const override;

  // The step's residual r(x1) (N) from `start`: for tests that check a step independently.
  Eigen::VectorXd residual(const Model& model, const State& start, double h,
                           const Eigen::VectorXd& x1);
  // The discrete-gradient spring force F(x0, x1) alone (N, 3n), for tests.
  static void springForces(const Model& model, const double* x0, const double* x1, double* f);
  // h^2/2 dr/dx1 at x1 from `start`, the matrix Newton factors: for the finite-difference test.
  const SparseMatrix& newtonMatrix(const Model& model, const State& start, double h,
                                   const Eigen::VectorXd& x1);

 private:
  void bind(const Model& model);
  // The discrete-gradient spring forces of `springs` (n points) added to f.
  static void addDiscreteGradient(const std::vector<Spring>& springs, std::ptrdiff_t n,
                                  const double* x0, const double* x1, double* f);
  // r at x1 into r_, and the scale its relative test divides by; from (x0, v0), step h.
  double evaluate(const Model& model, const State& s, double h, const Eigen::VectorXd& x1);
  // One step of h from s, retried as two halves while unconverged; depth halvings so far.
  StepResult advance(const Model& model, State& s, double h, int depth);
  // Newton for a step of h from s: x1_ holds the answer; converged says whether it met the
  // tolerance.
  StepResult solve(const Model& model, const State& s, double h, bool& converged);
  // Springs alone: x1_ changed rigidly (by the order of Newton's residual) so that the step
  // keeps the linear and angular momentum to round-off.
  void keepMomenta(const Model& model, const State& s, double h);
  // h^2/2 of the Newton matrix at x1_ (its midpoint xm_ last evaluated) into A_, and its
  // symmetric midpoint part into S_.
  void assemble(const Model& model, const State& s, double h);
  // S_ factored (CHOLMOD), the preconditioner of the next solves.
  StepResult factor();
  // delta_ = -A_^-1 (h^2/2) r_ by BiCGSTAB preconditioned by S_'s factor, to a relative residual
  // of `tolerance`.
  StepResult solveNewton(double h, double tolerance);

  ImplicitOptions options_;
  // The implicit midpoint step, whose energy merit carries Newton through the strongly
  // nonlinear start (a guess x0 + h v0 that crushes springs): Newton on the discrete gradient
  // starts from its answer, a step away by O(h^3).
  ImplicitMidpoint midpoint_;
  State guess_;
  long modelId_ = -1;
  std::unique_ptr<JacobianAssembler> jacobian_;
  SparseMatrix A_;
  // A_ the exact Newton matrix, S_ its symmetric part as the midpoint's (clamped: SPD), factored
  // by CHOLMOD as BiCGSTAB's preconditioner.
  SparseMatrix S_;
  std::unique_ptr<SpdSolver> spd_;
  std::unique_ptr<SparseLuFallback> lu_;  // where BiCGSTAB stalls
  long krylovIterations_ = 0, luFallbacks_ = 0;
  std::vector<Spring> springs_;  // the model's, listed once in bind()
  Eigen::VectorXd x1_, trial_, r_, delta_, xm_, vm_, f_, fRest_, fElastic_, fContact_, work_;
  bool stepUnconverged_ = false;
  bool springDamping_ = false;  // any spring with damping
  bool isolated_ = false;       // the last evaluation had springs alone (no damping)
  long steps_ = 0, iterations_ = 0, unconverged_ = 0, retries_ = 0, factorizations_ = 0;
  long extended_ = 0;  // solves past the cap while converging (solvers/methods/newton_cap.h)
  long lineSearchCuts_ = 0;
  long maxIterations_ = 0;
};

}  // namespace jello
