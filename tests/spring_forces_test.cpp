// Spring forces against their energy, conservation laws, and an analytic solution.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "solvers/methods/explicit_integrators.h"
#include "src/base/parallel.h"
#include "src/model.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// jello.w with every point displaced at random: no spring at rest length.
State deformedJello(const World& w, unsigned seed, double amount) {
  State s = initialState(w);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) s.x[i] += u(rng);
  for (Eigen::Index i = 0; i < s.v.size(); ++i) s.v[i] = u(rng) * 100;
  return s;
}

TEST(SpringForces, EqualMinusTheGradientOfTheSpringEnergy) {
  const World w = test::loadWorld("jello.w");
  const Model model(test::freeCube(w));
  State s = deformedJello(w, 1, 0.03);
  s.v.setZero();  // damping forces are not conservative
  Eigen::VectorXd f;
  model.forces(s.x, s.v, f);
  const double h = 1e-6;
  double worst = 0.0;
  for (Eigen::Index i = 0; i < s.x.size(); i += 7) {
    Eigen::VectorXd xp = s.x, xm = s.x;
    xp[i] += h;
    xm[i] -= h;
    const double grad =
        (model.springs().energy(xp.data()) - model.springs().energy(xm.data())) / (2 * h);
    worst = std::max(worst, std::abs(f[i] + grad) / (std::abs(f[i]) + 1e-3));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(SpringForces, ConserveLinearAndAngularMomentumWithDamping) {
  const World w = test::loadWorld("jello.w");
  const Model model(test::freeCube(w));
  const State s = deformedJello(w, 2, 0.05);
  Eigen::VectorXd f;
  model.forces(s.x, s.v, f);
  const int n = model.numPoints();
  Vec3 total, torque;
  double scale = 0.0;
  for (int p = 0; p < n; ++p) {
    const Vec3 fp = State::at(f, p);
    total += fp;
    torque += cross(s.position(p), fp);
    scale += norm(fp);
  }
  EXPECT_LT(norm(total), 1e-12 * scale);
  EXPECT_LT(norm(torque), 1e-12 * scale);
}

TEST(SpringForces, FreeCubeKeepsItsMomentumUnderRK4) {
  const World w = test::loadWorld("jello.w");
  const Model model(test::freeCube(w));
  State s = initialState(w);
  auto momentum = [&](const State& st) {
    Vec3 m;
    for (int p = 0; p < st.numPoints(); ++p) m += st.velocity(p) * model.mass();
    return m;
  };
  const Vec3 start = momentum(s);
  RungeKutta4 rk4;
  for (int i = 0; i < 400; ++i) ASSERT_TRUE(rk4.step(model, s, w.dt).ok);
  const Vec3 end = momentum(s);
  EXPECT_LT(norm(end - start), 1e-11 * norm(start));
}

// RK4 on two threads at 32^3 (each thread updating its own points, Model::acceleration's then)
// keeps what the physics keeps: an undamped free cube, deformed, moving and spinning, keeps its
// linear and angular momentum (central spring forces) and its energy to RK4's small error.
TEST(SpringForces, RK4OnTwoThreadsKeepsAFreeSpinningCubesMomentaAndEnergy) {
  World w = resampleCube(test::loadWorld("jello.w"), 32);
  w.dElastic = 0.0;
  const Model model(test::freeCube(w));
  State s = initialState(w);
  const int n = model.numPoints();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  const Vec3 c = s.centroid();
  for (int p = 0; p < n; ++p) {
    const Vec3 r = s.position(p) - c;
    State::set(s.x, p, s.position(p) + Vec3{jitter(rng), jitter(rng), jitter(rng)});
    State::set(s.v, p, Vec3{0.3, -0.2, 0.1} + Vec3{-2.0 * r.y, 2.0 * r.x + r.z, -r.y});
  }
  const auto linear = [&](const State& st) {
    return Vec3{st.v.head(n).sum(), st.v.segment(n, n).sum(), st.v.tail(n).sum()} * model.mass();
  };
  const Vec3 p0 = linear(s), l0 = model.angularMomentum(s);
  const double e0 = model.energy(s).total();
  setParallelThreads(2);
  ASSERT_EQ(model.pointBlocks().threads, 2);
  RungeKutta4 rk4;
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(rk4.step(model, s, 2e-5).ok);
  setParallelThreads(1);
  EXPECT_LT(norm(linear(s) - p0), 1e-12 * norm(p0));
  EXPECT_LT(norm(model.angularMomentum(s) - l0), 1e-9 * norm(l0));
  EXPECT_NEAR(model.energy(s).total(), e0, 1e-6 * e0);
  EXPECT_GT(model.energy(s).spring, 1e-3 * e0);  // deformed: the springs work
}

// Both cores (src/base/parallel.h): the threaded evaluation splits the points into one block per
// thread, each run in two halves; it equals the serial sum to round-off, for 2 and 3 threads, at
// 16^3 and 32^3 on a deformed moving cube, as do the springs' energy and a whole RK4 step. Below
// kParallelMinPoints (16^3: at 8^3) each is the serial result, bit for bit.
TEST(SpringForces, ThreadedEvaluationEqualsTheSerialOne) {
  for (int n : {8, 16, 32}) {
    const World w = resampleCube(test::loadWorld("jello.w"), n);
    const Model model(w);
    State s = initialState(w);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.02, 0.02);
    for (Eigen::Index i = 0; i < s.x.size(); ++i) {
      s.x[i] += jitter(rng);
      s.v[i] += 10.0 * jitter(rng);
    }
    setParallelThreads(1);
    Eigen::VectorXd serial = Eigen::VectorXd::Zero(s.x.size());
    model.springs().accumulate(s.x.data(), s.v.data(), serial.data());
    const double serialEnergy = model.springs().energy(s.x.data());
    State serialStep = s;  // and a whole RK4 step
    ASSERT_TRUE(RungeKutta4().step(model, serialStep, 1e-4).ok);
    for (int threads : {2, 3}) {
      SCOPED_TRACE(std::to_string(n) + "^3, " + std::to_string(threads) + " threads");
      setParallelThreads(threads);
      Eigen::VectorXd threaded = Eigen::VectorXd::Zero(s.x.size());
      model.springs().accumulate(s.x.data(), s.v.data(), threaded.data());
      EXPECT_LE((threaded - serial).cwiseAbs().maxCoeff(), 1e-12 * serial.cwiseAbs().maxCoeff());
      const double energy = model.springs().energy(s.x.data());
      EXPECT_NEAR(energy, serialEnergy, 1e-12 * serialEnergy);
      State step = s;
      ASSERT_TRUE(RungeKutta4().step(model, step, 1e-4).ok);
      EXPECT_LE((step.x - serialStep.x).cwiseAbs().maxCoeff(), 1e-13);
      EXPECT_LE((step.v - serialStep.v).cwiseAbs().maxCoeff(),
                1e-12 * (serialStep.v - s.v).cwiseAbs().maxCoeff());
      if (n * n * n < kParallelMinPoints) {
        EXPECT_EQ(threaded, serial);
        EXPECT_EQ(energy, serialEnergy);
        EXPECT_EQ(step.x, serialStep.x);
      }
      EXPECT_GT(serial.cwiseAbs().maxCoeff(), 1.0);
      EXPECT_GT(serialEnergy, 1.0);
    }
    setParallelThreads(1);
  }
}

TEST(SingleSpring, MatchesItsAnalyticSolution) {
  // Two masses m on a spring k, stretched by A from rest: the length oscillates as
  // L0 + A cos(w t) with w = sqrt(2k/m) (reduced mass m/2).
  const double k = 50.0, m = 0.01, L0 = 0.3, A = 0.05;
  const Model model(test::singleSpring(k, 0.0, L0, m));
  State s;
  s.x = Eigen::VectorXd::Zero(6);
  s.v = Eigen::VectorXd::Zero(6);
  s.x[1] = L0 + A;  // point 1 x
  const double w = std::sqrt(2 * k / m), h = 1e-4;
  RungeKutta4 rk4;
  double worst = 0.0;
  for (int i = 1; i <= 2000; ++i) {
    ASSERT_TRUE(rk4.step(model, s, h).ok);
    const double length = s.x[1] - s.x[0];
    worst = std::max(worst, std::abs(length - (L0 + A * std::cos(w * s.t))));
    EXPECT_NEAR(s.x[0] + s.x[1], L0 + A, 1e-12);  // centre of mass at rest
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(SingleSpring, DampingRemovesEnergyAtTheAnalyticRate) {
  // Relative motion: (m/2) l'' = -k (l - L0) - c l'. Energy ratio after time t of a weakly
  // damped oscillator decays as exp(-2 zeta w t) on average; check one full period.
  const double k = 50.0, m = 0.01, c = 0.01, L0 = 0.3, A = 0.05;
  const Model model(test::singleSpring(k, c, L0, m));
  State s;
  s.x = Eigen::VectorXd::Zero(6);
  s.v = Eigen::VectorXd::Zero(6);
  s.x[1] = L0 + A;
  const double mu = m / 2, w0 = std::sqrt(k / mu), gamma = c / (2 * mu);
  const double wd = std::sqrt(w0 * w0 - gamma * gamma), h = 1e-5;
  RungeKutta4 rk4;
  for (int i = 0; i < 5000; ++i) ASSERT_TRUE(rk4.step(model, s, h).ok);
  // Exact damped solution with l(0) = L0 + A, l'(0) = 0.
  const double t = s.t;
  const double exact =
      L0 + A * std::exp(-gamma * t) * (std::cos(wd * t) + gamma / wd * std::sin(wd * t));
  EXPECT_NEAR(s.x[1] - s.x[0], exact, 1e-9);
}

}  // namespace
}  // namespace jello
