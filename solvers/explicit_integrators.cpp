#include "solvers/explicit_integrators.h"

#include "src/parallel.h"

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
  // Stage slopes: k_x = v_stage, k_v = a(x_stage, v_stage). Between the four accelerations,
  // one fused pass over the state each (four passes in all instead of fourteen vector
  // expressions: at 32^3 the state no longer stays in cache), split over threads from
  // kParallelMinPoints points up; every value is computed as the expressions did.
  const long size = s.x.size();
  xs_.resize(size);
  vs_.resize(size);
  a_.resize(size);
  dx_.resize(size);
  dv_.resize(size);
  // Seven distinct arrays: restrict lets the passes vectorize without overlap checks.
  double* __restrict x = s.x.data();
  double* __restrict v = s.v.data();
  double* __restrict xs = xs_.data();
  double* __restrict vs = vs_.data();
  const double* __restrict a = a_.data();
  double* __restrict dx = dx_.data();
  double* __restrict dv = dv_.data();
  const int threads = s.numPoints() >= kParallelMinPoints ? parallelThreads() : 1;
  const auto pass = [&](const auto& body) {
    if (threads <= 1) return body(0L, size);
    runParallel(threads, [&](int t) { body(size * t / threads, size * (t + 1) / threads); });
  };
  const double half = 0.5 * h;
  // Stage 1 at (x, v); stage 2 at (x + h/2 k1x, v + h/2 k1v).
  model.acceleration(x, v, a_.data());
  pass([&](long lo, long hi) {
    for (long i = lo; i < hi; ++i) {
      xs[i] = x[i] + half * v[i];
      vs[i] = v[i] + half * a[i];
      dx[i] = v[i] + 2.0 * vs[i];
      dv[i] = a[i];
    }
  });
  // Stage 3 at (x + h/2 k2x, v + h/2 k2v); k2x is the stage-2 velocity vs.
  model.acceleration(xs, vs, a_.data());
  pass([&](long lo, long hi) {
    for (long i = lo; i < hi; ++i) {
      dv[i] += 2.0 * a[i];
      xs[i] = x[i] + half * vs[i];
      vs[i] = v[i] + half * a[i];
      dx[i] += 2.0 * vs[i];
    }
  });
  // Stage 4 at (x + h k3x, v + h k3v).
  model.acceleration(xs, vs, a_.data());
  pass([&](long lo, long hi) {
    for (long i = lo; i < hi; ++i) {
      dv[i] += 2.0 * a[i];
      xs[i] = x[i] + h * vs[i];
      vs[i] = v[i] + h * a[i];
      dx[i] += vs[i];
    }
  });
  model.acceleration(xs, vs, a_.data());
  const double sixth = h / 6.0;
  pass([&](long lo, long hi) {
    for (long i = lo; i < hi; ++i) {
      dv[i] += a[i];
      x[i] += sixth * dx[i];
      v[i] += sixth * dv[i];
    }
  });
  s.t += h;
  return StepResult::success();
}

}  // namespace jello
