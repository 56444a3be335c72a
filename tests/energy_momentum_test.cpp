// energy-momentum (solvers/methods/energy_momentum.h): the discrete gradient keeps every
// spring's energy, the total energy and both momenta at any step, dissipates exactly the
// damping's work, and is second order.
#include "solvers/methods/energy_momentum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/energy_momentum_support.h"

namespace jello {
namespace {

using test::angularMomentum;
using test::expectConserved;
using test::spinningCube;
using test::tight;
using test::unconvergedSteps;

// Each spring's discrete-gradient force does exactly minus the change of its energy over any
// move (F . (x1 - x0) = -(U(x1) - U(x0))), whatever the move, and is central (no net force).
TEST(EnergyMomentum, TheSpringsDiscreteGradientDoesExactlyTheirEnergysChange) {
  const World w = buildWorld(vibratingStiffCube(1e4));
  const Model model(w);
  const State s = initialState(w);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.02);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd x1 = s.x;
    for (Eigen::Index i = 0; i < x1.size(); ++i) x1[i] += normal(rng);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x1.size());
    EnergyMomentum::springForces(model, s.x.data(), x1.data(), f.data());
    const double u0 = model.potentialEnergy(s.x.data()), u1 = model.potentialEnergy(x1.data());
    EXPECT_NEAR(f.dot(x1 - s.x), -(u1 - u0), 1e-12 * std::abs(u1 - u0) + 1e-14);
    const int n = s.numPoints();
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.segment(c * n, n).sum(), 0.0, 1e-9);
  }
}

// Newton's matrix is the residual's Jacobian: (2/h^2) A p against central differences of r along
// random directions p, at a state a step into the spinning stretched cube (springs stretched,
// moving), undamped (exact: the springs' discrete gradient) and damped (the damping taken at the
// midpoint as the model's Jacobian gives it: without the damping force's change with the springs'
// directions, a quasi-Newton matrix), each against the change of the forces alone.
void expectJacobianMatchesDifferences(double c, double tolerance) {
  SCOPED_TRACE("c " + std::to_string(c));
  const World w = spinningCube(1e4, c);
  const Model model(w);
  const State s = initialState(w);
  const double h = 0.01;
  EnergyMomentum method(tight());
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd x1 = s.x + h * s.v;
  for (Eigen::Index i = 0; i < x1.size(); ++i) x1[i] += 1e-3 * normal(rng);
  const SparseMatrix a = method.newtonMatrix(model, s, h, x1);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd p(x1.size());
    for (Eigen::Index i = 0; i < p.size(); ++i) p[i] = normal(rng);
    const double eps = 1e-6;
    const Eigen::VectorXd fd =
        (method.residual(model, s, h, x1 + eps * p) - method.residual(model, s, h, x1 - eps * p)) /
        (2.0 * eps);
    const Eigen::VectorXd jp = (2.0 / (h * h)) * (a * p);
    // Against the forces' part alone (the inertia's 2M/h^2 p is most of r's change).
    const Eigen::VectorXd forces = fd - (2.0 * model.mass() / (h * h)) * p;
    // Shown for the record; asserted on the next line.
    std::printf("c %g: off by %.3g of the forces' change\n", c, (jp - fd).norm() / forces.norm());
    EXPECT_LT((jp - fd).norm(), tolerance * forces.norm()) << "direction " << trial;
  }
}

TEST(EnergyMomentum, NewtonsMatrixIsTheResidualsJacobian) {
  expectJacobianMatchesDifferences(0.0, 1e-8);  // measured 6.6e-11
  expectJacobianMatchesDifferences(5.0, 2e-3);  // measured 8.1e-4
}

// 20 steps here (a few seconds); 1,000 in the soak run (tests/energy_momentum_soak_test.cpp).
TEST(EnergyMomentum, KeepsTheEnergyAndAngularMomentumOfTheSpinningStretchedCube) {
  for (double k : {1e4, 1e5, 1e6}) expectConserved(k, 20);
}

// With spring damping: each step's energy falls by exactly the work the damping does on the
// midpoint velocity, (f(x_m, v_m) - f(x_m, 0)) . (x1 - x0), computed here from the model alone.
TEST(EnergyMomentum, TheEnergyFallsByExactlyTheDampingsWork) {
  const World w = spinningCube(1e4, 5.0);
  const Model model(w);
  State s = initialState(w);
  EnergyMomentum method(tight());
  const double e0 = model.energy(s).total();
  double dissipated = 0.0;
  Eigen::VectorXd fm, frest;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(s.v.size());
  for (int i = 0; i < 50; ++i) {
    const State before = s;
    ASSERT_TRUE(method.step(model, s, 0.01).ok);
    const Eigen::VectorXd xm = 0.5 * (before.x + s.x), vm = (s.x - before.x) / 0.01;
    model.forces(xm, vm, fm);
    model.forces(xm, zero, frest);
    const double work = (fm - frest).dot(s.x - before.x);
    ASSERT_LE(work, 0.0);
    dissipated += work;
    const double change = model.energy(s).total() - model.energy(before).total();
    EXPECT_NEAR(change, work, 1e-9 * e0) << "step " << i;
  }
  EXPECT_LT(dissipated, -0.1 * e0);  // the damping did something
  EXPECT_EQ(unconvergedSteps(method), 0);
}

// Second order: over 0.1 s of the spinning cube at k = 100 (h w_max 0.27 at h = 0.01: the
// asymptotic range; at k = 1e4, h w_max 2.7, the stiff modes are stepped over and no order
// shows) the positions' error against a step 32 times smaller falls 4x per halving of h.
TEST(EnergyMomentum, IsSecondOrder) {
  const World w = spinningCube(100.0, 0.25);
  const Model model(w);
  const auto run = [&](double h) {
    State s = initialState(w);
    EnergyMomentum method(tight());
    const int steps = static_cast<int>(std::lround(0.1 / h));
    for (int i = 0; i < steps; ++i) EXPECT_TRUE(method.step(model, s, h).ok);
    return s.x;
  };
  const Eigen::VectorXd reference = run(0.01 / 32);
  double errors[3];
  for (int i = 0; i < 3; ++i) {
    errors[i] = (run(0.01 / double(1 << i)) - reference).cwiseAbs().maxCoeff();
  }
  std::printf("errors %.3g %.3g %.3g\n", errors[0], errors[1], errors[2]);
  // Measured 2.70, then 2.27: approaching 2 from above (no lower order hides in it).
  EXPECT_GE(std::log2(errors[0] / errors[1]), 1.8);
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), 2.0, 0.35);
}

// Linear momentum: a free cube's centre of mass moves at its constant velocity, exactly.
TEST(EnergyMomentum, KeepsTheLinearMomentum) {
  SceneSpec spec = vibratingStiffCube(1e5);
  spec.velocity = {0.3, -0.2, 0.1};
  const World w = buildWorld(spec);
  const Model model(w);
  State s = initialState(w);
  EnergyMomentum method(tight());
  const Vec3 c0 = test::centre(s);
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(method.step(model, s, 0.01).ok);
  const Vec3 moved = test::centre(s) - c0;
  EXPECT_NEAR(moved.x, 0.3 * 0.2, 1e-10);
  EXPECT_NEAR(moved.y, -0.2 * 0.2, 1e-10);
  EXPECT_NEAR(moved.z, 0.1 * 0.2, 1e-10);
}

// Contact: the course creator's cube thrown into the walls and the plane (penalty contact,
// spring and contact damping, no field): every step converges and the energy never rises: the
// contact's work is exactly its energy's change, and the damping only takes.
TEST(EnergyMomentum, ThroughContactTheEnergyNeverRises) {
  const World w = buildWorld(SceneSpec{});
  Simulation sim(w, IntegratorKind::EnergyMomentum, 0.01, tight());
  const double e0 = sim.model().energy(sim.state()).total();
  double previous = e0;
  for (int i = 0; i < 60; ++i) {  // through the first wall and the plane
    ASSERT_TRUE(sim.step().ok) << i;
    const double e = sim.model().energy(sim.state()).total();
    EXPECT_LE(e, previous + 1e-9 * e0) << "step " << i;
    previous = e;
  }
  EXPECT_EQ(unconvergedSteps(sim.integrator()), 0);
}

}  // namespace
}  // namespace jello
