#include "solvers/methods/explicit_integrators.h"

#include <cstddef>
#include <initializer_list>

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

namespace {

// RK4's updates on the component indices [lo, hi) (one component of a range of points). Free
// functions with restrict arguments, so that they vectorize (through a lambda's captures the
// compiler would have to check seven arrays for overlap, and gives up).

// After stage 1 at (x, v): stage 2's state (x + h/2 k1x, v + h/2 k1v) and the slopes' sums.
void afterStage1(std::ptrdiff_t lo, std::ptrdiff_t hi, double h, const double* __restrict x,
                 const double* __restrict v, const double* __restrict a, double* __restrict xs,
                 double* __restrict vs, double* __restrict dx, double* __restrict dv) {
  for (std::ptrdiff_t i = lo; i < hi; ++i) {
    dv[i] = a[i];
    xs[i] = x[i] + (0.5 * h) * v[i];
    vs[i] = v[i] + (0.5 * h) * a[i];
    dx[i] = v[i] + 2.0 * vs[i];
  }
}

// After stage 2 (scale 1/2, weight 2) or 3 (scale 1, weight 1): the next stage's state
// (x + scale h k_x, v + scale h k_v), k_x the stage's velocity vs.
void afterStage(std::ptrdiff_t lo, std::ptrdiff_t hi, double h, double scale, double weight,
                const double* __restrict x, const double* __restrict v, const double* __restrict a,
                double* __restrict xs, double* __restrict vs, double* __restrict dx,
                double* __restrict dv) {
  for (std::ptrdiff_t i = lo; i < hi; ++i) {
    dv[i] += 2.0 * a[i];
    xs[i] = x[i] + (scale * h) * vs[i];
    vs[i] = v[i] + (scale * h) * a[i];
    dx[i] += weight * vs[i];
  }
}

// After stage 4: the step.
void afterStage4(std::ptrdiff_t lo, std::ptrdiff_t hi, double h, double* __restrict x,
                 double* __restrict v, const double* __restrict a, const double* __restrict dx,
                 const double* __restrict dv) {
  for (std::ptrdiff_t i = lo; i < hi; ++i) {
    x[i] += (h / 6.0) * dx[i];
    v[i] += (h / 6.0) * (dv[i] + a[i]);
  }
}

}  // namespace

StepResult RungeKutta4::step(const Model& model, State& s, double h) {
  // Stage slopes: k_x = v_stage, k_v = a(x_stage, v_stage). Each stage's update of the next
  // stage's state runs on the points whose acceleration is final (Model::acceleration's then),
  // on the thread that computed them, one component at a time.
  const std::ptrdiff_t n = model.numPoints();
  // In this order (the order the first edition's expressions allocated them): allocated xs_
  // first, the springs ran 10-16% slower at 16^3, the arrays they read and write falling on the
  // same offsets within a 4 KiB page (jello-sim, one core, alternating runs).
  for (Eigen::VectorXd* w : {&a_, &dx_, &dv_, &xs_, &vs_}) w->resize(3 * n);
  double *x = s.x.data(), *v = s.v.data(), *xs = xs_.data(), *vs = vs_.data(), *a = a_.data(),
         *dx = dx_.data(), *dv = dv_.data();
  const auto each = [n](std::ptrdiff_t lo, std::ptrdiff_t hi, const auto& update) {
    for (std::ptrdiff_t e = 0; e < 3; ++e) update(e * n + lo, e * n + hi);
  };
  model.acceleration(x, v, a, [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
    each(lo, hi, [&](std::ptrdiff_t i0, std::ptrdiff_t i1) {
      afterStage1(i0, i1, h, x, v, a, xs, vs, dx, dv);
    });
  });
  for (const double scale : {0.5, 1.0}) {  // stages 2 and 3
    model.acceleration(xs, vs, a, [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
      each(lo, hi, [&](std::ptrdiff_t i0, std::ptrdiff_t i1) {
        afterStage(i0, i1, h, scale, 1.0 / scale, x, v, a, xs, vs, dx, dv);
      });
    });
  }
  model.acceleration(xs, vs, a, [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
    each(lo, hi,
         [&](std::ptrdiff_t i0, std::ptrdiff_t i1) { afterStage4(i0, i1, h, x, v, a, dx, dv); });
  });
  s.t += h;
  return StepResult::success();
}

}  // namespace jello
