// Integrators against their exact amplification factors and their orders of convergence.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "solvers/integrator_factory.h"
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

// The integrator table's traits (src/world/integrator_table.h) are what each row's integrator
// does: on the exactly linear oscillator its linear model predicts its energy, its family says
// whether it has a stability limit, and every trait has a name. A row added with a wrong trait
// fails here; one without a trait does not compile.
double energyRatio(IntegratorKind kind, double y, int steps, bool worst = false) {
  const Oscillator osc;
  const std::unique_ptr<Integrator> method = makeIntegrator(kind);
  State s = osc.start();
  const double e0 = osc.energy(s), h = y / osc.omega();
  double largest = 0.0;
  for (int i = 0; i < steps; ++i) {
    if (!method->step(osc.model, s, h).ok) return std::numeric_limits<double>::infinity();
    largest = std::max(largest, osc.energy(s) / e0);
  }
  return worst ? largest : osc.energy(s) / e0;
}

TEST(IntegratorTable, EveryRowsLinearModelPredictsItsIntegratorOnALinearOscillator) {
  for (IntegratorKind kind : allIntegrators()) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    const LinearModel model = linearModel(kind);
    EXPECT_NE(linearModelName(model), "?");
    EXPECT_NE(familyName(integratorFamily(kind)), "?");
    EXPECT_EQ(isExplicit(kind), hasStabilityLimit(model));
    EXPECT_EQ(integratorFamily(kind) == IntegratorFamily::Cvode, model == LinearModel::Adaptive);
    EXPECT_EQ(isExplicit(kind) || model == LinearModel::Adaptive, !isAStable(model));
    switch (model) {
      case LinearModel::ForwardEuler:
        EXPECT_NEAR(energyRatio(kind, 0.5, 1), eulerFactor(0.5), 1e-12);
        break;
      case LinearModel::SymplecticEuler:
        EXPECT_LT(energyRatio(kind, 1.9, 2000, true), 25.0);
        EXPECT_GT(energyRatio(kind, 2.1, 40, true), 1e9);
        break;
      case LinearModel::RungeKutta4:
        EXPECT_NEAR(energyRatio(kind, 2.0, 1), rk4Factor(2.0), 1e-12);
        break;
      case LinearModel::BackwardEuler:  // energy x 1/(1 + y^2) a step, at any y
        EXPECT_NEAR(energyRatio(kind, 3.0, 1), 0.1, 1e-6);
        // Five steps: 1e-20 of the energy left (more, and the two points meet in round-off,
        // where a spring of rest length 0 has no direction).
        EXPECT_LT(energyRatio(kind, 100.0, 5, true), 1.0);
        EXPECT_LT(energyRatio(kind, 100.0, 5), 1e-16);
        break;
      case LinearModel::Bdf2:  // damps the fast modes, the slow ones by far less
        EXPECT_LT(energyRatio(kind, 100.0, 5), 1e-3);
        // Backward Euler would keep 1/1.09^20 = 0.18 (most of BDF2's loss is its first step,
        // backward Euler's).
        EXPECT_GT(energyRatio(kind, 0.3, 20), 0.8);
        break;
      case LinearModel::Trapezoidal:  // keeps the energy of a linear mode at any step
        EXPECT_NEAR(energyRatio(kind, 3.0, 20), 1.0, 1e-6);
        EXPECT_NEAR(energyRatio(kind, 100.0, 20), 1.0, 1e-6);
        break;
      case LinearModel::Adaptive:  // follows the motion to its tolerance, whatever the interval
        EXPECT_NEAR(energyRatio(kind, 1.0, 10), 1.0, 1e-3);
        EXPECT_NEAR(energyRatio(kind, 30.0, 2), 1.0, 1e-3);
        break;
    }
  }
}

}  // namespace
}  // namespace jello
