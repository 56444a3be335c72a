// Implicit integrators solved to convergence by Newton's method (src/PHYSICS.md, "Implicit
// steps solved to convergence"). Each writes its step as equations in the new positions y:
//   r(y) = gamma/h^2 M (y - y_pred) - f(x_e, v_e) = 0,
//   x_e = theta y + (1 - theta) x0,   v_e = sigma y + v_c,   v_new = sigma_new y + v_new_c,
// with r in newtons:
//   implicit  backward Euler       gamma 1,   theta 1,   v_e = (y - x0)/h = v_new,
//                                  y_pred = x0 + h v0
//   midpoint  implicit midpoint    gamma 2,   theta 1/2, v_e = (y - x0)/h,
//                                  v_new = 2 (y - x0)/h - v0, y_pred = x0 + h v0
//   newmark   average acceleration gamma 4,   theta 1,   v_e = 2 (y - x0)/h - v0 = v_new,
//                                  y_pred = x0 + h v0 + h^2/4 a0
//   bdf2      second-order BDF     gamma 9/4, theta 1,   v_e = (3 y - 4 x1 + x0)/(2h) = v_new,
//                                  y_pred = (4 x1 - x0)/3 + 2h/9 (4 v1 - v0)
//             (x1, v1 the current state, x0, v0 the one before). The first step, and any step
//             after a change of h, of the model or of the state from outside, starts from a
//             history made up behind the start: x_-1 = x0 - h v0, v_-1 = v0 - h a, with a =
//             (v_BE - v0)/h the acceleration of a backward-Euler pilot step of h (bounded on
//             stiff modes, where a0 itself is not). Both are O(h^2) off, so BDF2 stays second
//             order; the pilot costs one more Newton solve per start; the halves of an
//             unconverged step start by backward Euler. Measured on the spinning stretched stiff
//             cube (0.2 s, k = 1e4 and 1e5), the angular momentum kept by each start:
//               backward Euler (before)                     98.74% (its first step costs 2.5%)
//               this history                                100.03%
//               the same with x_-1 += h^2/2 a                100.69%
//               v_-1 = v0 (constant velocity)                100.03%, but first order
//               Taylor, a = a0                               blows up on the stiff modes
//               m backward-Euler-started BDF2 sub-steps      98.85% at m = 2, 98.0-98.5% at 4, 8
//               trapezoidal                                  16% (its energy gain carried on)
//               implicit midpoint                            111.6% (stiff modes left undamped)
//             Every start's loss or gain is in its first three steps, as the stiff vibration
//             is damped.
// Newton: J = dr/dy = gamma/h^2 M - theta K - sigma D, solved as
//   (M - (sigma h^2/gamma) D - (theta h^2/gamma) K) delta = -(h^2/gamma) r
// By default the factorization of that matrix is kept across iterations and steps (modified
// Newton) and renewed only when an iteration shrinks the residual by less than refactorRatio,
// or when h, the method's coefficients or the model change: any SPD matrix gives a descent
// direction of the merit below, so the line search and the stopping tests are unchanged and
// the converged step is the same (tested); K and D are still assembled at every iterate for
// the merit's damping term.
// with K's springs projected to semidefinite (the compression clamp), so the matrix is SPD and
// delta a descent direction of the step's merit function
//   E_k(y) = gamma/(2h^2) |y - y_pred|_M^2 + (U(x_e) - F_k . x_e)/theta + Psi_k(v_e)/sigma,
// U the spring and contact energy, F_k the field and user force at the iterate, Psi_k(v) =
// -1/2 v^T D_k v the damping dissipation with the spring directions and contact normals of the
// iterate. Its gradient at the iterate is exactly r, so Newton's fixed point is the step's
// equations with every force where the method evaluates it: damping and the field are not
// approximated, only frozen inside one iteration's line search. A backtracking (Armijo) line
// search on E_k makes the iterations descend; where no step of at least 2^-12 of the update
// descends (an indefinite unclamped Hessian), the whole update is taken and counted.
// Newton stops when the residual is below newtonTolerance relative to |gamma/h^2 M (y - y_pred)|
// + |f|, or when a Newton update moves no coordinate more than newtonPositionTolerance (m), the
// update then taken whole: the absolute floor that ends the iterations at rest, where round-off
// keeps the relative test from being met. A step
// that reaches newtonMaxIterations is retried as two half steps of h/2 (each retried so in turn,
// down to h / 2^newtonHalvings: a contact whose onset the full step jumped over is met by the
// halves); a sub-step still unconverged at that floor is accepted, counted, and the step returns
// StepResult::unconverged, never silent. bdf2's halves start by backward Euler (another h, no
// pilot). With barrier contact (src/world/contact_law.h) the guess and every update are bounded so
// that no point (neither y nor x_e) reaches a solid: the line search starts at 0.9 of the
// largest feasible step, and the merit, infinite inside, rejects the rest (Li et al. 2020).
// Optionally (seedIterations) Newton starts where a few iterations with the constant projective
// matrix P = M + L(a c + b k) left the inertial guess: for backward Euler these are projective
// dynamics' iterations (solvers/methods/projective_integrator.h), for every method a descent that
// needs no assembly and no factorization; Newton then has less far to go. The step is the same.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <utility>

#include "solvers/integrator.h"
#include "solvers/linalg/chebyshev_weights.h"
#include "solvers/system/implicit_system.h"

namespace jello {

// The affine maps of one step (see above) in the displacement d = y - x0, which is small, so
// the inertia term loses no digits to the size of the positions; all vectors 3n.
struct ImplicitStepForm {
  double gamma = 1.0, theta = 1.0, sigma = 1.0, sigmaNew = 1.0;
  Eigen::VectorXd x0;         // positions at the step's start (y = x0 + d)
  Eigen::VectorXd dPred;      // y_pred - x0
  Eigen::VectorXd vConst;     // v_e = sigma d + vConst
  Eigen::VectorXd vNewConst;  // v_new = sigmaNew d + vNewConst
};

class NewtonIntegrator : public Integrator {
 public:
  explicit NewtonIntegrator(const ImplicitOptions& options = {});
  explicit NewtonIntegrator(const SolverOptions& options) : NewtonIntegrator(options.implicit) {}

  StepResult step(const Model& model, State& state, double h) override;
  std::vector<Statistic> statistics() const override;

  // The last step's Newton iterations (its retries' included) and final relative residual.
  int lastIterations() const { return lastIterations_; }
  double lastResidual() const { return lastResidual_; }
  bool lastConverged() const { return lastConverged_; }
  long unconvergedSteps() const { return unconverged_; }
  long retriedSteps() const { return retries_; }  // (sub-)steps retried as two halves
  const SpdSolver& linearSolver() const { return system_.solver(); }

  // The step's residual r(y) (N) and Newton matrix J = dr/dy (N/m) at y from `start`, for
  // tests that check them independently of the solver. The form is the one step() would use.
  Eigen::VectorXd residual(const Model& model, const State& start, double h,
                           const Eigen::VectorXd& y);
  SparseMatrix newtonMatrix(const Model& model, const State& start, double h,
                            const Eigen::VectorXd& y);

 protected:
  // Fills f, the method's form for a step of h from `state` (f's vectors are reused).
  virtual void form(const Model& model, const State& state, double h, ImplicitStepForm& f) = 0;
  // Called with the state an accepted step ended at (history for multistep methods).
  virtual void accepted(const State& after, double h) { (void)after, (void)h; }
  // A multistep method without history for a step of h from `state` may ask for a pilot: the
  // step its form gives then (bdf2: backward Euler), taken first and handed to piloted(), after
  // which the step is taken again with what the method made of it.
  virtual bool wantsPilot(const State& state, double h) const {
    return (void)state, (void)h, false;
  }
  virtual void piloted(const State& start, const State& pilot, double h) {
    (void)start, (void)pilot, (void)h;
  }

 private:
  void bind(const Model& model);
  // inertia = gamma/h^2; all three work on form_.
  void evaluate(const Model& model, double inertia, const Eigen::VectorXd& d);
  double merit(const Model& model, double inertia, const Eigen::VectorXd& d);
  // Assembles K and D at the iterate and, when `refactor`, factors
  // A = M - (sigma h^2/gamma) D - (theta h^2/gamma) K there.
  StepResult prepareNewtonMatrix(double h, bool refactor);
  // prepareNewtonMatrix, then the update into delta_ (clamped on demand: see the .cpp).
  StepResult solveNewton(double h, bool refactor);
  // The barrier's bounds on a Newton update delta from d: the largest s <= 1 with y, and with
  // x_e, outside every solid along s delta (Model::contactStepBound).
  std::pair<double, double> barrierStepBounds(const Model& model, const Eigen::VectorXd& d,
                                              const Eigen::VectorXd& delta);
  // options_.seedIterations projective iterations on d_ (ImplicitOptions::seedIterations).
  StepResult seed(const Model& model, double inertia, double h);
  std::pair<double, double> matrixCoefficients(double h) const;
  // A step of h, retried as two halves while unconverged (see above); depth halvings so far.
  StepResult advance(const Model& model, State& s, double h, int depth, int& iterations);
  // Newton's iterations for a step of h from s into d_ and form_; s unchanged.
  StepResult solve(const Model& model, const State& s, double h, bool& converged, int& iterations);

  ImplicitOptions options_;
  ImplicitSystem system_;
  // The factor in the system: valid for these coefficients a, b of A until the model changes.
  bool factorValid_ = false;
  double factorA_ = 0.0, factorB_ = 0.0;
  // Workspaces: positions and velocities where forces are evaluated, force, residual, update.
  ImplicitStepForm form_;  // the current step's
  Eigen::VectorXd d_, dTrial_, xe_, ve_, f_, r_, rhs_, delta_, trial_, external_;
  Eigen::VectorXd previousSeed_;  // the seed iterate before d_ (Chebyshev)
  int lastIterations_ = 0;
  double lastResidual_ = 0.0;
  bool lastConverged_ = true;
  long steps_ = 0, iterations_ = 0, maxIterations_ = 0, cuts_ = 0, searchFailures_ = 0,
       unconverged_ = 0, retries_ = 0, reuses_ = 0, seeds_ = 0;
  long extended_ = 0;        // solves past the cap while converging (solvers/methods/newton_cap.h)
  long clampFallbacks_ = 0;  // updates solved again clamped (ImplicitOptions::clampOnDemand)
  bool stepUnconverged_ = false;  // a sub-step of the current step was accepted unconverged
  ChebyshevWeights seedWeights_;  // the seed iterations' (ImplicitOptions::seedChebyshevRho)
};

// The four methods state only their forms; construction is the base's (ImplicitOptions or
// SolverOptions).
// implicit: backward Euler.
class BackwardEuler final : public NewtonIntegrator {
 public:
  using NewtonIntegrator::NewtonIntegrator;
  IntegratorKind kind() const override { return IntegratorKind::Implicit; }

 protected:
  void form(const Model& model, const State& state, double h, ImplicitStepForm& f) override;
};

// midpoint: implicit midpoint rule.
class ImplicitMidpoint final : public NewtonIntegrator {
 public:
  using NewtonIntegrator::NewtonIntegrator;
  IntegratorKind kind() const override { return IntegratorKind::Midpoint; }

 protected:
  void form(const Model& model, const State& state, double h, ImplicitStepForm& f) override;
};

// newmark: average-acceleration Newmark (gamma 1/2, beta 1/4), the trapezoidal rule.
class Newmark final : public NewtonIntegrator {
 public:
  using NewtonIntegrator::NewtonIntegrator;
  IntegratorKind kind() const override { return IntegratorKind::Newmark; }

 protected:
  void form(const Model& model, const State& state, double h, ImplicitStepForm& f) override;

 private:
  Eigen::VectorXd a0_;
};

// bdf2: second-order backward differentiation, started from a history a backward-Euler pilot
// step makes up (above).
class Bdf2 final : public NewtonIntegrator {
 public:
  using NewtonIntegrator::NewtonIntegrator;
  IntegratorKind kind() const override { return IntegratorKind::Bdf2; }
  void restart() override { history_ = false; }

 protected:
  void form(const Model& model, const State& state, double h, ImplicitStepForm& f) override;
  void accepted(const State& after, double h) override;
  bool wantsPilot(const State& state, double h) const override;
  void piloted(const State& start, const State& pilot, double h) override;

 private:
  // True when a step of h from `state` continues the last one (the history holds).
  bool continues(const State& state, double h) const;
  bool history_ = false;
  // The state before the last step, the current step's start, and the last step's result.
  State previous_, current_, last_;
  double h_ = 0.0;
};

}  // namespace jello
