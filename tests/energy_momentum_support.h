// What energy-momentum's tests share (tests/energy_momentum_test.cpp, and its 1,000-step runs in
// tests/energy_momentum_soak_test.cpp): Newton solved to round-off, the spinning stretched cube,
// and the conservation check.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "solvers/methods/energy_momentum.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello::test {

inline SolverOptions tight() {
  SolverOptions o;
  o.implicit.newtonTolerance = 1e-13;
  o.implicit.newtonPositionTolerance = 1e-15;
  o.implicit.newtonMaxIterations = 100;
  return o;
}

// The spinning, 5% stretched stiff cube with spring damping c (the walls never reached).
inline World spinningCube(double k, double c) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = c;
  return buildWorld(spec);
}

inline long unconvergedSteps(const Integrator& method) {
  return std::lround(*findStatistic(method.statistics(), "newton_unconverged_steps"));
}

// The undamped spinning stretched cube (the walls never reached), dt = 0.01, far beyond every
// explicit limit (h w_max 2.7 at k = 1e4 to 27 at 1e6): every step converged, the total energy
// to 1e-9 of itself and the angular momentum to 1e-11 over `steps` steps.
inline void expectConserved(double k, int steps) {
  SCOPED_TRACE("k " + std::to_string(k));
  const World w = spinningCube(k, 0.0);
  const Model model(w);
  State s = initialState(w);
  EnergyMomentum method(tight());
  const double e0 = model.energy(s).total();
  const Eigen::Vector3d l0 = angularMomentum(model, s);
  double worstE = 0.0, worstL = 0.0;
  for (int i = 0; i < steps; ++i) {
    const StepResult r = method.step(model, s, 0.01);
    ASSERT_TRUE(r.ok) << i << ": " << r.message;
    worstE = std::max(worstE, std::abs(model.energy(s).total() - e0) / e0);
    worstL = std::max(worstL, (angularMomentum(model, s) - l0).norm() / l0.norm());
  }
  // Shown for the record; asserted just below.
  std::printf("k %g, %d steps: energy within %.3g, angular momentum within %.3g\n", k, steps,
              worstE, worstL);
  EXPECT_EQ(unconvergedSteps(method), 0);
  EXPECT_LT(worstE, 1e-9);   // measured at most 3.7e-14 over 1,000 steps
  EXPECT_LT(worstL, 1e-11);  // measured at most 3.0e-12 over 1,000 steps
}

}  // namespace jello::test
