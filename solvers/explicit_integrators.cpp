#include "solvers/explicit_integrators.h"

namespace jello {

StepResult ExplicitEuler::step(const Model& model, State& s, double h) {
  model.acceleration(s.x, s.v, a_);
  s.x += h * s.v;
  s.v += h * a_;
  s.t += h;
  return StepResult::success();
}

StepResult SymplecticEuler::step(const Model& model, State& s, double h) {
  model.acceleration(s.x, s.v, a_);
  s.v += h * a_;
  s.x += h * s.v;
  s.t += h;
  return StepResult::success();
}

StepResult RungeKutta4::step(const Model& model, State& s, double h) {
  // Stage slopes: k_x = v_stage, k_v = a(x_stage, v_stage).
  // Stage 1 at (x, v).
  model.acceleration(s.x, s.v, a_);
  dx_ = s.v;
  dv_ = a_;
  // Stage 2 at (x + h/2 k1x, v + h/2 k1v).
  xs_ = s.x + (0.5 * h) * s.v;
  vs_ = s.v + (0.5 * h) * a_;
  dx_ += 2.0 * vs_;
  model.acceleration(xs_, vs_, a_);
  dv_ += 2.0 * a_;
  // Stage 3 at (x + h/2 k2x, v + h/2 k2v); k2x is the stage-2 velocity vs_.
  xs_ = s.x + (0.5 * h) * vs_;
  vs_ = s.v + (0.5 * h) * a_;
  dx_ += 2.0 * vs_;
  model.acceleration(xs_, vs_, a_);
  dv_ += 2.0 * a_;
  // Stage 4 at (x + h k3x, v + h k3v).
  xs_ = s.x + h * vs_;
  vs_ = s.v + h * a_;
  dx_ += vs_;
  model.acceleration(xs_, vs_, a_);
  dv_ += a_;

  s.x += (h / 6.0) * dx_;
  s.v += (h / 6.0) * dv_;
  s.t += h;
  return StepResult::success();
}

}  // namespace jello
