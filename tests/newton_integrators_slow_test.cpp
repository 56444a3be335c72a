// The converged implicit integrators over longer runs (ctest label `slow`): orders of
// convergence, the angular momentum of a spinning stretched stiff cube, and a model reassigned
// at the same address.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>

#include "solvers/integrator_factory.h"
#include "solvers/methods/explicit_integrators.h"
#include "solvers/methods/linearized_backward_euler.h"
#include "solvers/methods/newton_integrators.h"
#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

using test::angularMomentum;
using test::kConverged;
using test::positionsAt;
using test::SmallCube;

TEST(NewtonIntegrators, ConvergeWithTheirOrders) {
  const SmallCube cube;
  RungeKutta4 rk4;
  const Eigen::VectorXd ref = positionsAt(cube, rk4, 2.5e-6, 0.02);
  const double steps[3] = {2e-4, 1e-4, 5e-5};
  for (IntegratorKind kind : kConverged) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    ImplicitOptions o;
    o.newtonTolerance = 1e-12;
    o.newtonPositionTolerance = 1e-14;
    double errors[3];
    for (int i = 0; i < 3; ++i) {
      auto method = test::makeConverged(kind, o);
      errors[i] = (positionsAt(cube, *method, steps[i], 0.02) - ref).cwiseAbs().maxCoeff();
    }
    const double order = kind == IntegratorKind::Implicit ? 1.0 : 2.0;
    EXPECT_NEAR(std::log2(errors[0] / errors[1]), order, 0.2);
    EXPECT_NEAR(std::log2(errors[1] / errors[2]), order, 0.15);
  }
}

// The spinning, 5% stretched stiff cube, undamped, h = 0.01, for 0.2 s: how much angular
// momentum about the centre of mass each method keeps.
// Every step must converge: a step accepted at the iteration cap keeps what it keeps by chance.
double angularMomentumKept(IntegratorKind kind, double k, double newtonTolerance = 1e-8) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = 0.0;
  SolverOptions options;
  options.implicit.newtonTolerance = newtonTolerance;
  options.implicit.newtonPositionTolerance = newtonTolerance * 1e-2;
  // The clamped Hessian converges linearly on this compressed-and-stretched cube: about 12
  // iterations to 1e-11, more to 1e-13.
  options.implicit.newtonMaxIterations = 200;
  // The trapezoidal rule's equations have several solutions on this cube: plain Newton reaches
  // the one the table reports; with the factor kept (the default), Newton was measured leaving
  // 3 of 20 steps unconverged at 200 iterations and ending elsewhere. The other methods are
  // measured as users run them.
  options.implicit.reuseFactor = kind != IntegratorKind::Newmark;
  // The integrator alone, not a Simulation: newmark's energy gain here is what Simulation
  // reports as a divergence, and this test measures the method.
  const World w = buildWorld(spec);
  const Model model(w);
  State s = initialState(w);
  const std::unique_ptr<Integrator> method = makeIntegrator(kind, options);
  const Eigen::Vector3d L0 = angularMomentum(model, s);
  for (int i = 0; i < 20; ++i) EXPECT_TRUE(method->step(model, s, 0.01).ok) << integratorName(kind);
  for (const Statistic& stat : method->statistics()) {
    if (stat.name == "newton_unconverged_steps") {
      EXPECT_EQ(stat.value, 0.0) << integratorName(kind);
    }
  }
  return angularMomentum(model, s).dot(L0) / L0.squaredNorm();
}

TEST(NewtonIntegrators, KeepTheAngularMomentumOfASpinningStretchedCube) {
  for (double k : {1e4, 1e5}) {
    SCOPED_TRACE("k " + std::to_string(k));
    const double implicit = angularMomentumKept(IntegratorKind::Implicit, k);
    EXPECT_GE(implicit, 0.97);
    // Midpoint conserves it exactly for central forces, up to Newton's residual: measured
    // 1e-13 at a relative residual of 1e-13 (5e-8 at 1e-10, 2e-10 at 1e-12); backward Euler
    // loses 2.5% in its first step.
    EXPECT_NEAR(angularMomentumKept(IntegratorKind::Midpoint, k, 1e-13), 1.0, 1e-9);
    // BDF2 started from a history made up behind the start by a backward-Euler pilot: measured
    // 100.03% at both k (a backward-Euler start kept 98.74%; solvers/methods/newton_integrators.h
    // lists the starts measured).
    const double bdf2 = angularMomentumKept(IntegratorKind::Bdf2, k);
    std::printf("at k = %g: bdf2 keeps %.5f of the angular momentum\n", k, bdf2);
    EXPECT_GE(bdf2, 0.99);
    EXPECT_LE(bdf2, 1.001);
    // The linearized step pins the rotation (src/PHYSICS.md: measured 0.038 at k = 1e4, 0.0014
    // at 1e5), and the trapezoidal rule (newmark) gains on this stiff nonlinear problem.
    const double linear = angularMomentumKept(IntegratorKind::ImplicitLinear, k);
    const double newmark = angularMomentumKept(IntegratorKind::Newmark, k);
    std::printf("at k = %g: implicit-linear keeps %.4f of the angular momentum, newmark %.4f\n", k,
                linear, newmark);
    EXPECT_LT(linear, 0.1);
    // Converged, the trapezoidal rule neither keeps nor damps it on this stiff nonlinear
    // problem (h w_max about 290 at k = 1e5): it gains at k = 1e4 (measured 1.3875 on both
    // machines), and at k = 1e5 its figure follows the rounding (1.0076 where the spring pass ran
    // in AVX-512, 0.1061 in AVX2 on a Zen 3 VM, the same code): only the gain is bounded, to the
    // measured figure, so that a gain that grows fails.
    EXPECT_LE(newmark, 1.40);
    if (k < 5e4) {
      EXPECT_GE(newmark, 1.3);
    }
  }
}

TEST(NewtonIntegrators, AReassignedModelAtTheSameAddressIsBoundAfresh) {
  // Step one model, assign a stiffer one into the same variable, step again: the integrator
  // must take the new model, exactly as a fresh integrator does.
  for (IntegratorKind kind : {IntegratorKind::Implicit, IntegratorKind::ImplicitLinear,
                              IntegratorKind::Cvode, IntegratorKind::Bdf2}) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    const World soft = buildWorld(stiffCube(1e3)), hard = buildWorld(stiffCube(1e5));
    Model model(soft);
    const Model* address = &model;
    std::unique_ptr<Integrator> reused = makeIntegrator(kind);
    State s = initialState(soft);
    ASSERT_TRUE(reused->step(model, s, 0.01).ok);
    model = Model(hard);
    ASSERT_EQ(&model, address);
    State fresh = s;
    ASSERT_TRUE(reused->step(model, s, 0.01).ok);
    std::unique_ptr<Integrator> other = makeIntegrator(kind);
    ASSERT_TRUE(other->step(model, fresh, 0.01).ok);
    EXPECT_LE((s.v - fresh.v).cwiseAbs().maxCoeff(), 1e-9 * fresh.v.cwiseAbs().maxCoeff());
  }
}

// jello.w at 16^3 and h = 0.01 hits the walls at speed. The penalty's damping -dc (n.v) n acts
// on the solid side only, so the residual jumps where a point reaches a wall: there the step's
// equations may have no root, and Newton was seen cycling between iterates on either side
// (relative residual 0.84 and 0.016 for 30 iterations, 200 did not help). Without the
// contact's damping the same steps converge: the steps left unconverged are the model's jump,
// not the solver's failing (solvers/README.md, "implicit"). Retries in half steps (halvings)
// are off unless asked for: the jump is the model's at any step.
long unconvergedStepsOfJelloAt16(double contactDamping, int halvings = 0) {
  World w = resampleCube(test::loadWorld("jello.w"), 16);
  w.dCollision = contactDamping;
  const Model model(w);
  State s = initialState(w);
  ImplicitOptions o;
  o.newtonHalvings = halvings;
  const std::unique_ptr<Integrator> method = std::make_unique<BackwardEuler>(o);
  for (int i = 0; i < 6; ++i) {
    EXPECT_TRUE(method->step(model, s, 0.01).ok);
    EXPECT_TRUE(s.x.allFinite() && s.v.allFinite());
  }
  for (const Statistic& stat : method->statistics()) {
    if (stat.name == "newton_unconverged_steps") return std::lround(stat.value);
  }
  ADD_FAILURE() << "no newton_unconverged_steps statistic";
  return -1;
}

TEST(NewtonIntegrators, StepsLeftUnconvergedOnJelloAreTheContactDampingsJump) {
  const World w = test::loadWorld("jello.w");
  ASSERT_GT(w.dCollision, 0.0);
  const long withDamping = unconvergedStepsOfJelloAt16(w.dCollision);
  std::printf("jello.w at 16^3, h = 0.01, 6 steps: %ld unconverged\n", withDamping);
  EXPECT_GE(withDamping, 1);  // reported (counted), not hidden
  EXPECT_EQ(unconvergedStepsOfJelloAt16(0.0), 0);
  // Retried in halves (the default), the steps whose onset the full step jumped over converge.
  const long retried = unconvergedStepsOfJelloAt16(w.dCollision, ImplicitOptions{}.newtonHalvings);
  std::printf("the same, retried in halves down to 1/16: %ld unconverged\n", retried);
  EXPECT_LT(retried, withDamping);
}

}  // namespace
}  // namespace jello
