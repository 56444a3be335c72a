// Backward Euler, converged (implicit) and linearized (implicit-linear): the exact energy loss,
// order of convergence, Newton residual, linear solvers.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "solvers/linalg/linear_solver.h"
#include "solvers/methods/explicit_integrators.h"
#include "solvers/methods/linearized_backward_euler.h"
#include "solvers/methods/newton_integrators.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// On a linear system one Newton iteration is the exact step: both keep 1/(1 + y^2) of it.
template <class Method>
void expectBackwardEulerEnergyFactor() {
  const test::LinearOscillator osc;
  for (double y : {0.1, 1.0, 10.0}) {
    Method be;
    State s = osc.start();
    const double h = y / osc.omega();
    for (int i = 0; i < 10; ++i) {
      const double before = osc.energy(s);
      ASSERT_TRUE(be.step(osc.model, s, h).ok);
      EXPECT_NEAR(osc.energy(s) / before, 1.0 / (1.0 + y * y), 1e-10) << "y " << y << " step " << i;
    }
  }
}

TEST(BackwardEuler, UndampedLinearSpringKeepsOneOverOnePlusH2W2OfItsEnergyPerStep) {
  expectBackwardEulerEnergyFactor<BackwardEuler>();
}

TEST(LinearizedBackwardEuler, UndampedLinearSpringKeepsOneOverOnePlusH2W2OfItsEnergyPerStep) {
  expectBackwardEulerEnergyFactor<LinearizedBackwardEuler>();
}

using test::positionsAt;
using test::SmallCube;

TEST(BackwardEuler, ConvergesWithOrderOneTowardRK4) {
  const SmallCube cube;
  RungeKutta4 rk4;
  const Eigen::VectorXd ref = positionsAt(cube, rk4, 2.5e-6, 0.02);
  double errors[3];
  const double steps[3] = {1e-4, 5e-5, 2.5e-5};  // h w_max from 0.13 down: asymptotic
  for (int i = 0; i < 3; ++i) {
    BackwardEuler be;
    errors[i] = (positionsAt(cube, be, steps[i], 0.02) - ref).cwiseAbs().maxCoeff();
  }
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), 1.0, 0.15);
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), 1.0, 0.1);
}

// Runs 20 converged steps and checks the implicit equations
//   x1 = x0 + h v1,   M (v1 - v0) = h f(x1, v1)
// independently of the integrator's own residual. Returns the most iterations a step needed.
int expectExactBackwardEulerSteps(const SmallCube& cube, double tolerance) {
  ImplicitOptions options;
  options.reuseFactor = false;  // plain Newton: a fresh Jacobian every iteration
  options.newtonMaxIterations = 30;
  options.newtonTolerance = tolerance;
  options.newtonPositionTolerance = 1e-300;          // the residual alone ends the iterations
  options.clampCompression = false;                  // the exact spring Jacobian
  options.linearSolver = LinearSolverKind::Cholmod;  // exact solves: CG's are inexact early on
  BackwardEuler be(options);
  State s = initialState(cube.world);
  const double h = 2e-3;
  int most = 0;
  for (int i = 0; i < 20; ++i) {
    const State before = s;
    EXPECT_TRUE(be.step(cube.model, s, h).ok);
    EXPECT_LE(be.lastResidual(), tolerance) << "step " << i;
    most = std::max(most, be.lastIterations());
    Eigen::VectorXd f;
    cube.model.forces(s.x, s.v, f);
    const Eigen::VectorXd g = cube.model.mass() * (s.v - before.v) - h * f;
    EXPECT_LE(g.norm(),
              2 * tolerance * (cube.model.mass() * (s.v - before.v).norm() + h * f.norm()));
    EXPECT_LE((s.x - before.x - h * s.v).cwiseAbs().maxCoeff(), 1e-14);
  }
  return most;
}

TEST(BackwardEuler, NewtonConvergesQuadraticallyWithTheExactJacobian) {
  // Without damping the assembled K is the exact Jacobian: each iteration squares the
  // residual, down to 1e-10 within 5 iterations (the first starts from x0 + h v0).
  SmallCube cube;
  cube.world.dElastic = 0.0;
  cube.model = Model(test::freeCube(cube.world));
  EXPECT_LE(expectExactBackwardEulerSteps(cube, 1e-10), 5);
}

TEST(BackwardEuler, NewtonDrivesTheResidualBelowTheToleranceWithDamping) {
  // Spring damping's x-derivative is left out of the matrix, so convergence is linear and ends
  // at the tolerance.
  const SmallCube cube;
  EXPECT_LE(expectExactBackwardEulerSteps(cube, 1e-8), 15);
}

template <class Method>
void expectTheThreeLinearSolversTakeTheSameStep() {
  const SmallCube cube;
  State ref = initialState(cube.world);
  ImplicitOptions base;
  base.newtonTolerance = 1e-12;
  base.linearSolver = LinearSolverKind::Cholmod;
  Method cholmod(base);
  ASSERT_TRUE(cholmod.step(cube.model, ref, 0.01).ok);
  for (LinearSolverKind kind : {LinearSolverKind::Ldlt, LinearSolverKind::Cg}) {
    ImplicitOptions options = base;
    options.linearSolver = kind;
    options.cgTolerance = 1e-12;
    Method be(options);
    State s = initialState(cube.world);
    ASSERT_TRUE(be.step(cube.model, s, 0.01).ok);
    EXPECT_LT((s.v - ref.v).cwiseAbs().maxCoeff(), 1e-8 * ref.v.cwiseAbs().maxCoeff())
        << linearSolverName(kind);
  }
}

TEST(BackwardEuler, TheThreeLinearSolversTakeTheSameStep) {
  expectTheThreeLinearSolversTakeTheSameStep<BackwardEuler>();
}

TEST(LinearizedBackwardEuler, TheThreeLinearSolversTakeTheSameStep) {
  expectTheThreeLinearSolversTakeTheSameStep<LinearizedBackwardEuler>();
}

TEST(LinearizedBackwardEuler, FallsBackToLdltWhenTheUnclampedSystemIsIndefinite) {
  // Every spring at half its rest length, k = 10^4, h = 0.01: with the clamp off,
  // M - h^2 K has negative directions and the LLT fails.
  World w = buildWorld(stiffCube(1e4));
  for (Vec3& x : w.positions) x = Vec3{0.5, 0.5, 0.5} + (x - Vec3{0.5, 0.5, 0.5}) * 0.5;
  w.positions.back() = Vec3{0.5, 0.5, 0.5} + Vec3{0.25, 0.25, 0.25};
  const Model model(w);
  ImplicitOptions options;
  options.clampCompression = false;
  options.linearSolver = LinearSolverKind::Cholmod;
  LinearizedBackwardEuler be(options);
  State s = initialState(w);
  const StepResult r = be.step(model, s, 0.01);
  EXPECT_EQ(be.linearSolver().stats().fallbacks, 1) << r.message;
  // Either a checked LDLT solution or a clear failure; never a silent NaN.
  if (r.ok) {
    EXPECT_TRUE(s.x.allFinite() && s.v.allFinite());
  } else {
    EXPECT_FALSE(r.message.empty());
  }
}

// CG that meets a direction of negative curvature falls back to LDLT too, and keeps it until
// the next matrix: [[1 2 0] [2 1 0] [0 0 1]] has eigenvalues 3, -1, 1 and a positive diagonal.
TEST(SpdSolver, CgFallsBackToLdltOnAnIndefiniteMatrix) {
  SparseMatrix A(3, 3);
  const std::vector<Eigen::Triplet<double, int>> entries = {
      {0, 0, 1.0}, {1, 1, 1.0}, {2, 2, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}};
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  SpdSolver solver(LinearSolverKind::Cg, 1e-12);
  ASSERT_TRUE(solver.factorize(A).ok);
  const Eigen::Vector3d b(1.0, -1.0, 0.5);
  for (int i = 0; i < 2; ++i) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(3);
    ASSERT_TRUE(solver.solve(b, x).ok);
    EXPECT_LT((A * x - b).norm(), 1e-12);
  }
  EXPECT_EQ(solver.stats().fallbacks, 1);  // the second solve used the kept LDLT
}

}  // namespace
}  // namespace jello
