// What the implicit-integrator tests share: the four converged methods, a factory over their
// options, a small free cube and a run over it, and angular momentum about the centre of mass.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "solvers/methods/newton_integrators.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello::test {

inline constexpr IntegratorKind kConverged[] = {IntegratorKind::Implicit, IntegratorKind::Midpoint,
                                                IntegratorKind::Newmark, IntegratorKind::Bdf2};

inline std::unique_ptr<NewtonIntegrator> makeConverged(IntegratorKind kind,
                                                       const ImplicitOptions& o = {}) {
  switch (kind) {
    case IntegratorKind::Implicit:
      return std::make_unique<BackwardEuler>(o);
    case IntegratorKind::Midpoint:
      return std::make_unique<ImplicitMidpoint>(o);
    case IntegratorKind::Newmark:
      return std::make_unique<Newmark>(o);
    case IntegratorKind::Bdf2:
      return std::make_unique<Bdf2>(o);
    default:
      return nullptr;
  }
}

// A 4^3 free cube, jello.w's deformed pose and motion resampled, walls and plane off.
struct SmallCube {
  World world = resampleCube(loadWorld("jello.w"), 4);
  Model model{freeCube(world)};
};

// The positions after running `method` on the cube for T seconds at step h (each step checked).
inline Eigen::VectorXd positionsAt(const SmallCube& cube, Integrator& method, double h, double T) {
  State s = initialState(cube.world);
  const long steps = std::lround(T / h);
  for (long i = 0; i < steps; ++i) EXPECT_TRUE(method.step(cube.model, s, h).ok);
  return s.x;
}

// About the centre of mass, computed here from the state (an oracle apart from Model's).
inline Eigen::Vector3d angularMomentum(const Model& model, const State& s) {
  const int n = s.numPoints();
  const Eigen::Vector3d c(s.x.head(n).mean(), s.x.segment(n, n).mean(), s.x.tail(n).mean());
  Eigen::Vector3d L = Eigen::Vector3d::Zero();
  for (int p = 0; p < n; ++p) {
    const Eigen::Vector3d r(s.x[p] - c.x(), s.x[n + p] - c.y(), s.x[2 * n + p] - c.z());
    const Eigen::Vector3d v(s.v[p], s.v[n + p], s.v[2 * n + p]);
    L += model.mass() * r.cross(v);
  }
  return L;
}

// The backward-Euler step from `start` solved tightly (Newton to 1e-12, positions to 1e-14): the
// reference projective's iterations must approach. Fails the test if Newton does not converge.
inline State backwardEulerStep(const Model& model, const State& start, double h) {
  ImplicitOptions o;
  o.newtonTolerance = 1e-12;
  o.newtonPositionTolerance = 1e-14;
  o.newtonMaxIterations = 200;
  BackwardEuler be(o);
  State s = start;
  EXPECT_TRUE(be.step(model, s, h).ok);
  EXPECT_TRUE(be.lastConverged());
  return s;
}

}  // namespace jello::test
