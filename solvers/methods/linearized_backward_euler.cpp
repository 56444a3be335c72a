#include "solvers/methods/linearized_backward_euler.h"

#include <algorithm>

namespace jello {

LinearizedBackwardEuler::LinearizedBackwardEuler(ImplicitOptions options)
    : options_(options), system_(options.linearSolverOptions(), options.clampCompression) {}

void LinearizedBackwardEuler::prepare(const Model& model) {
  if (system_.bind(model)) dv_.setZero(3 * model.numPoints());
}

StepResult LinearizedBackwardEuler::factorAndSolve(double h, const Eigen::VectorXd& rhs,
                                                   Eigen::VectorXd& x) {
  if (StepResult r = system_.factorize(h, h * h); !r.ok) return r;
  return system_.solve(rhs, x);
}

double LinearizedBackwardEuler::residual(const Model& model, const State& s, double h) {
  model.forces(x1_, v1_, f_);
  g_ = model.mass() * (v1_ - s.v);  // the momentum change, then minus the impulse
  const double scale = g_.norm() + h * f_.norm();
  g_ -= h * f_;
  return scale > 0.0 ? g_.norm() / scale : 0.0;
}

void LinearizedBackwardEuler::keepOutside(const Model& model, const State& s, double h) {
  x1_ = s.x + h * v1_;
  if (!model.barrierContact()) return;
  // The barrier: the move h v1 may not carry a point into a solid. Cut to 0.9 of the largest
  // that keeps every point out (the step is then not backward Euler's: counted).
  move_ = h * v1_;
  const double bound = model.contactStepBound(s.x.data(), move_.data());
  if (bound >= 1.0) return;
  v1_ *= 0.9 * bound;
  x1_ = s.x + h * v1_;
  ++barrierCuts_;
}

StepResult LinearizedBackwardEuler::step(const Model& model, State& s, double h) {
  prepare(model);
  // Friction's normal forces at the step's start, as the Newton methods take them (s.x is
  // written only at the end, after the last evaluation).
  const Model::FrictionLag lag(model, s.x.data());
  model.forces(s.x, s.v, f_);
  // First iteration, linearized at (x0, v0): rhs = h (f0 + h K v0).
  system_.assemble(s.x.data(), s.v.data());
  rhs_.noalias() = system_.K() * s.v;
  rhs_ = h * (f_ + h * rhs_);
  // dv_ still holds the last step's dv: a good first guess for CG.
  if (StepResult r = factorAndSolve(h, rhs_, dv_); !r.ok) return r;
  v1_ = s.v + dv_;
  keepOutside(model, s, h);

  int iterations = 1;
  lastResidual_ = 0.0;
  int maxIterations = 1;
  const double tolerance = options_.contactNewtonTolerance;
  if (model.contactBegins(s.x.data(), x1_.data())) {
    maxIterations = options_.contactNewtonIterations;
    ++contactSteps_;
  }
  bool unconverged = false;  // the contact onset's Newton stopped at its cap
  if (maxIterations > 1) {
    // Newton on g(v1): (M - h D - h^2 K)(x1, v1) delta = -g.
    for (;;) {
      lastResidual_ = residual(model, s, h);
      if (lastResidual_ <= tolerance) break;
      if (iterations >= maxIterations) {
        ++unconverged_;
        unconverged = true;
        break;
      }
      rhs_ = -g_;
      system_.assemble(x1_.data(), v1_.data());
      delta_.setZero(rhs_.size());  // a correction: small, so start CG from zero
      if (StepResult r = factorAndSolve(h, rhs_, delta_); !r.ok) return r;
      v1_ += delta_;
      keepOutside(model, s, h);
      ++iterations;
    }
  }
  lastIterations_ = iterations;
  newtonIterations_ += iterations;
  ++steps_;
  s.x = x1_;  // copied, not swapped: the state's storage stays put (Integrator::step)
  s.v = v1_;
  s.t += h;
  return unconverged ? StepResult::unconvergedSuccess() : StepResult::success();
}

std::vector<Statistic> LinearizedBackwardEuler::statistics() const {
  std::vector<Statistic> stats{
      {"newton_iterations", static_cast<double>(newtonIterations_)},
      {"newton_unconverged_steps", static_cast<double>(unconverged_)},
      {"contact_onset_steps", static_cast<double>(contactSteps_)},
      {"barrier_cuts", static_cast<double>(barrierCuts_)},
  };
  system_.appendStatistics(stats);
  return stats;
}

}  // namespace jello
