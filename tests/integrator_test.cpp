// Integrators against their exact amplification factors and their orders of convergence.
#include <gtest/gtest.h>

#include <cmath>

#include "solvers/methods/explicit_integrators.h"
#include "tests/test_support.h"

namespace jello {
namespace {

using Oscillator = test::LinearOscillator;

// Energy ratio per step on an undamped mode of frequency w, with y = h w.
double eulerFactor(double y) {
  return 1 + y * y;
}
double rk4Factor(double y) {
  return 1 - std::pow(y, 6) / 72 + std::pow(y, 8) / 576;
}

template <class Method>
void expectEnergyFactorPerStep(double y, double factor, int steps) {
  const Oscillator osc;
  Method method;
  State s = osc.start();
  const double h = y / osc.omega();
  for (int i = 0; i < steps; ++i) {
    const double before = osc.energy(s);
    ASSERT_TRUE(method.step(osc.model, s, h).ok);
    EXPECT_NEAR(osc.energy(s) / before, factor, 1e-12 * factor) << "step " << i;
  }
}

TEST(ExplicitEuler, GrowsAnUndampedOscillatorBySqrtOnePlusH2W2PerStep) {
  // Amplitude grows by sqrt(1 + h^2 w^2), so energy by 1 + h^2 w^2, at every h.
  for (double y : {0.01, 0.1, 0.5, 1.5})
    expectEnergyFactorPerStep<ExplicitEuler>(y, eulerFactor(y), 20);
}

TEST(RungeKutta4, ScalesAnUndampedOscillatorByItsStabilityPolynomial) {
  for (double y : {0.3, 1.0, 2.7, 2.9}) expectEnergyFactorPerStep<RungeKutta4>(y, rk4Factor(y), 20);
}

TEST(RungeKutta4, IsStableUpToTwoRootTwoOverOmega) {
  EXPECT_LT(rk4Factor(2.0 * std::sqrt(2.0) - 1e-3), 1.0);
  EXPECT_GT(rk4Factor(2.0 * std::sqrt(2.0) + 1e-3), 1.0);
}

double maxEnergyRatio(double y, int steps) {
  const Oscillator osc;
  SymplecticEuler method;
  State s = osc.start();
  const double e0 = osc.energy(s), h = y / osc.omega();
  double worst = 0.0;
  for (int i = 0; i < steps; ++i) {
    EXPECT_TRUE(method.step(osc.model, s, h).ok);
    worst = std::max(worst, osc.energy(s) / e0);
  }
  return worst;
}

TEST(SymplecticEuler, StaysBoundedBelowHwTwoAndBlowsUpAbove) {
  EXPECT_LT(maxEnergyRatio(0.5, 5000), 1.5);
  EXPECT_LT(maxEnergyRatio(1.9, 5000), 25.0);
  EXPECT_GT(maxEnergyRatio(2.1, 40), 1e9);
}

// Positions at T = 0.02 s of a deformed, moving free cube (jello.w without walls and plane).
Eigen::VectorXd positionsAt(Integrator& method, double h) {
  const World w = test::loadWorld("jello.w");
  const Model model(test::freeCube(w));
  State s = initialState(w);
  const long steps = std::lround(0.02 / h);
  for (long i = 0; i < steps; ++i) EXPECT_TRUE(method.step(model, s, h).ok);
  return s.x;
}

Eigen::VectorXd referencePositions() {
  RungeKutta4 rk4;
  return positionsAt(rk4, 0.02 / 4000);
}

double positionError(Integrator& method, double h, const Eigen::VectorXd& reference) {
  return (positionsAt(method, h) - reference).cwiseAbs().maxCoeff();
}

TEST(ExplicitEuler, ConvergesWithOrderOne) {
  const Eigen::VectorXd ref = referencePositions();
  ExplicitEuler euler;
  const double e1 = positionError(euler, 1e-4, ref);
  const double e2 = positionError(euler, 5e-5, ref);
  const double e3 = positionError(euler, 2.5e-5, ref);
  EXPECT_NEAR(std::log2(e1 / e2), 1.0, 0.15);
  EXPECT_NEAR(std::log2(e2 / e3), 1.0, 0.1);
}

TEST(SymplecticEuler, ConvergesWithOrderOne) {
  const Eigen::VectorXd ref = referencePositions();
  SymplecticEuler symplectic;
  const double e1 = positionError(symplectic, 1e-4, ref);
  const double e2 = positionError(symplectic, 5e-5, ref);
  EXPECT_NEAR(std::log2(e1 / e2), 1.0, 0.15);
}

TEST(RungeKutta4, ConvergesWithOrderFour) {
  const Eigen::VectorXd ref = referencePositions();
  RungeKutta4 rk4;
  const double e1 = positionError(rk4, 4e-4, ref);
  const double e2 = positionError(rk4, 2e-4, ref);
  const double e3 = positionError(rk4, 1e-4, ref);
  EXPECT_NEAR(std::log2(e1 / e2), 4.0, 0.3);
  EXPECT_NEAR(std::log2(e2 / e3), 4.0, 0.3);
}

}  // namespace
}  // namespace jello
