// The converged implicit integrators (implicit, midpoint, newmark, bdf2): each step satisfies the
// method's own equations (checked here from the states, not through the integrator's
// residual), the Newton matrix is the residual's derivative, Newton finishes at rest, the orders
// of convergence, midpoint's energy, and the angular momentum of a spinning stretched cube,
// which the linearized step (implicit-linear) loses.
#include "solvers/methods/newton_integrators.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "solvers/methods/explicit_integrators.h"
#include "solvers/methods/linearized_backward_euler.h"
#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

using test::kConverged;
using test::SmallCube;

// The method's equations, written out from the states (h, previous for bdf2), in newtons:
// the residual the step must drive to zero, with every force where the method evaluates it.
Eigen::VectorXd methodResidual(IntegratorKind kind, const Model& model, const State& before2,
                               const State& before, const State& after, double h,
                               bool bdf2Started) {
  const double m = model.mass();
  Eigen::VectorXd f;
  switch (kind) {
    case IntegratorKind::Implicit:
      EXPECT_LE((after.x - before.x - h * after.v).cwiseAbs().maxCoeff(), 1e-12);
      model.forces(after.x, after.v, f);
      return m * (after.v - before.v) / h - f;
    case IntegratorKind::Midpoint:
      EXPECT_LE((after.x - before.x - 0.5 * h * (before.v + after.v)).cwiseAbs().maxCoeff(), 1e-12);
      model.forces(0.5 * (before.x + after.x), 0.5 * (before.v + after.v), f);
      return m * (after.v - before.v) / h - f;
    case IntegratorKind::Newmark: {
      Eigen::VectorXd a0, f1;
      model.acceleration(before.x, before.v, a0);
      model.forces(after.x, after.v, f1);
      const Eigen::VectorXd a1 = f1 / m;
      EXPECT_LE((after.v - before.v - 0.5 * h * (a0 + a1)).cwiseAbs().maxCoeff(),
                1e-6 * after.v.cwiseAbs().maxCoeff());
      // The position equation, in newtons: 4m/h^2 (x1 - x0 - h v0) - m a0 - f1.
      return 4.0 * m / (h * h) * (after.x - before.x - h * before.v) - m * a0 - f1;
    }
    case IntegratorKind::Bdf2: {
      if (!bdf2Started) {
        // Started from a history made up behind the start by a backward-Euler pilot step,
        // taken here by an integrator of its own: x_-1 = x0 - h v0, v_-1 = v0 - (v_BE - v0).
        ImplicitOptions o;
        o.newtonTolerance = 1e-12;
        o.newtonPositionTolerance = 1e-300;
        BackwardEuler pilotStep(o);
        State pilot = before;
        EXPECT_TRUE(pilotStep.step(model, pilot, h).ok && pilotStep.lastConverged());
        State ghost = before;
        ghost.x -= h * before.v;
        ghost.v -= pilot.v - before.v;
        return methodResidual(kind, model, ghost, before, after, h, true);
      }
      EXPECT_LE((after.x - 4.0 / 3.0 * before.x + 1.0 / 3.0 * before2.x - 2.0 / 3.0 * h * after.v)
                    .cwiseAbs()
                    .maxCoeff(),
                1e-12);
      model.forces(after.x, after.v, f);
      return m * (3.0 * after.v - 4.0 * before.v + before2.v) / (2.0 * h) - f;
    }
    default:
      ADD_FAILURE();
      return {};
  }
}

TEST(NewtonIntegrators, EachConvergedStepSatisfiesItsMethodsEquations) {
  const SmallCube cube;  // damped, deformed, moving
  for (IntegratorKind kind : kConverged) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    ImplicitOptions o;
    o.newtonTolerance = 1e-10;
    o.newtonPositionTolerance = 1e-300;
    auto method = test::makeConverged(kind, o);
    State s = initialState(cube.world), prev = s;
    const double h = 2e-3;
    for (int i = 0; i < 10; ++i) {
      const State before = s;
      ASSERT_TRUE(method->step(cube.model, s, h).ok);
      ASSERT_TRUE(method->lastConverged()) << "step " << i;
      Eigen::VectorXd f;
      cube.model.forces(s.x, s.v, f);
      const double scale = cube.model.mass() * (s.v - before.v).norm() / h + f.norm();
      const Eigen::VectorXd r = methodResidual(kind, cube.model, prev, before, s, h, i > 0);
      EXPECT_LE(r.norm(), 1e-8 * scale) << "step " << i;
      prev = before;
    }
  }
}

// Newton's iterations a step of h from the cube's start needs with no cap (tolerance 1e-10).
int iterationsToConverge(const SmallCube& cube, IntegratorKind kind, double h) {
  ImplicitOptions o;
  o.newtonTolerance = 1e-10;
  o.newtonPositionTolerance = 1e-300;
  o.newtonMaxIterations = 200;
  auto method = test::makeConverged(kind, o);
  State s = initialState(cube.world);
  EXPECT_TRUE(method->step(cube.model, s, h).ok);
  EXPECT_TRUE(method->lastConverged());
  return method->lastIterations();
}

TEST(NewtonIntegrators, AnUnconvergedStepIsRetriedAsTheTwoHalfStepsThatConverge) {
  // Capped at what half a step needs, the full step cannot converge: it is retried as two
  // halves, and ends where two converged half steps taken by hand end. (Not newmark: on this
  // cube its half steps need as many iterations as its whole one, or more, from 0.01 to 0.04 s.
  // Nor bdf2: its first step is two solves, a pilot and the step, so a cap cannot single out
  // the whole step's. The retry is the base class's.)
  const SmallCube cube;
  const double h = 0.02;
  for (IntegratorKind kind : {IntegratorKind::Implicit, IntegratorKind::Midpoint}) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    const int full = iterationsToConverge(cube, kind, h),
              half = iterationsToConverge(cube, kind, h / 2);
    ASSERT_LT(half, full);  // the case the test is about
    ImplicitOptions o;
    o.newtonTolerance = 1e-10;
    o.newtonPositionTolerance = 1e-300;
    o.newtonMaxIterations = half;
    o.newtonCapFactor = 1;  // converging, the full step would go on past the cap
    auto retrying = test::makeConverged(kind, o);
    State s = initialState(cube.world);
    const StepResult r = retrying->step(cube.model, s, h);
    ASSERT_TRUE(r.ok);
    EXPECT_FALSE(r.unconverged);
    EXPECT_TRUE(retrying->lastConverged());
    EXPECT_EQ(retrying->retriedSteps(), 1);
    EXPECT_EQ(retrying->unconvergedSteps(), 0);
    EXPECT_NEAR(s.t, h, 1e-15);

    o.newtonHalvings = 0;
    auto byHand = test::makeConverged(kind, o);
    State halves = initialState(cube.world);
    int halvesIterations = 0;
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE(byHand->step(cube.model, halves, h / 2).ok);
      ASSERT_TRUE(byHand->lastConverged()) << "half " << i;
      halvesIterations += byHand->lastIterations();
    }
    // The step's iterations: the capped full attempt's and the halves'.
    EXPECT_EQ(retrying->lastIterations(), half + halvesIterations);
    EXPECT_LE((s.x - halves.x).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LE((s.v - halves.v).cwiseAbs().maxCoeff(), 1e-9 * halves.v.cwiseAbs().maxCoeff());
  }
}

TEST(NewtonIntegrators, AStepUnconvergedAtTheHalvingsFloorIsAcceptedFlaggedAndCounted) {
  const SmallCube cube;
  ImplicitOptions o;
  o.newtonTolerance = 1e-14;
  o.newtonPositionTolerance = 1e-300;
  o.newtonMaxIterations = 1;
  o.newtonHalvings = 2;
  BackwardEuler be(o);
  State s = initialState(cube.world);
  const StepResult r = be.step(cube.model, s, 0.02);
  ASSERT_TRUE(r.ok);
  EXPECT_TRUE(r.unconverged);
  EXPECT_FALSE(be.lastConverged());
  EXPECT_EQ(be.unconvergedSteps(), 1);        // one step, however many of its sub-steps
  EXPECT_EQ(be.retriedSteps(), 1 + 2);        // the step, then each of its halves
  EXPECT_EQ(be.lastIterations(), 1 + 2 + 4);  // one each: the step, its halves, their halves
  EXPECT_NEAR(s.t, 0.02, 1e-15);
  EXPECT_TRUE(s.x.allFinite() && s.v.allFinite());
}

TEST(NewtonIntegrators, TheNewtonMatrixIsTheResidualsDerivative) {
  // Undamped and unclamped, the assembled matrix is the exact Jacobian dr/dy.
  SmallCube cube;
  cube.world.dElastic = 0.0;
  cube.model = Model(test::freeCube(cube.world));
  ImplicitOptions o;
  o.clampCompression = false;
  const State start = initialState(cube.world);
  const double h = 5e-3;
  const Eigen::VectorXd y = start.x + h * start.v + 1e-3 * Eigen::VectorXd::Ones(start.x.size());
  for (IntegratorKind kind : kConverged) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    auto method = test::makeConverged(kind, o);
    const Eigen::MatrixXd J(method->newtonMatrix(cube.model, start, h, y));
    double worst = 0.0;
    const double eps = 1e-6;
    for (Eigen::Index j = 0; j < y.size(); j += 7) {
      Eigen::VectorXd yp = y, ym = y;
      yp[j] += eps;
      ym[j] -= eps;
      const Eigen::VectorXd column = (method->residual(cube.model, start, h, yp) -
                                      method->residual(cube.model, start, h, ym)) /
                                     (2 * eps);
      worst = std::max(worst, (column - J.col(j)).cwiseAbs().maxCoeff() / J.cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-6);
  }
}

TEST(NewtonIntegrators, NewtonFinishesAtRestAndOnceTheMotionStops) {
  // stiff-k1e5.w: undamped, k = 1e5, h = 0.01 (h w_max about 290): no step may end unconverged.
  const World w = test::loadWorld("stiff-k1e5.w");
  const Model model(w);
  BackwardEuler be;
  State s = initialState(w);
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(be.step(model, s, 0.01).ok);
    EXPECT_TRUE(be.lastConverged()) << "step " << i;
  }
  EXPECT_EQ(be.unconvergedSteps(), 0);

  // The lattice at rest, nothing acting: the first residual is zero, no iteration at all.
  World rest = buildWorld(stiffCube(1e5));
  const Lattice lat{rest.cubeResolution};
  for (int i = 0; i < lat.n; ++i)
    for (int j = 0; j < lat.n; ++j)
      for (int k = 0; k < lat.n; ++k)
        rest.positions[lat.index(i, j, k)] = lat.restPosition(i, j, k);
  for (Vec3& v : rest.velocities) v = {};
  const Model still(rest);
  State r = initialState(rest);
  for (IntegratorKind kind : kConverged) {
    auto method = test::makeConverged(kind);
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(method->step(still, r, 0.01).ok);
      // bdf2's first step is two solves: its backward-Euler pilot and the step.
      const bool piloted = kind == IntegratorKind::Bdf2 && i == 0;
      EXPECT_LE(method->lastIterations(), piloted ? 2 : 1) << integratorName(kind);
    }
  }

  // Damped (the stiff cube's 0.25 N s/m), backward Euler stops the vibration within a few
  // steps; from then on Newton needs at most 3 iterations.
  const World damped = buildWorld(stiffCube(1e5));
  const Model dampedModel(damped);
  BackwardEuler slow;
  State d = initialState(damped);
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(slow.step(dampedModel, d, 0.01).ok);
    ASSERT_TRUE(slow.lastConverged());
    if (i >= 40) {
      EXPECT_LE(slow.lastIterations(), 3) << "step " << i;
    }
  }
}

// On a linear system midpoint and the trapezoidal rule have |R| = 1 for every mode.
template <class Method>
void expectLinearSpringEnergyKeptAtHwTen() {
  const test::LinearOscillator osc;
  Method method;
  State s = osc.start();
  const double e0 = osc.energy(s), h = 10.0 / osc.omega();
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(method.step(osc.model, s, h).ok);
  EXPECT_NEAR(osc.energy(s) / e0, 1.0, 1e-9);
}

TEST(ImplicitMidpoint, ConservesTheEnergyOfAnUndampedLinearSpringAtHwTen) {
  expectLinearSpringEnergyKeptAtHwTen<ImplicitMidpoint>();
}

TEST(Newmark, ConservesTheEnergyOfAnUndampedLinearSpringAtHwTen) {
  expectLinearSpringEnergyKeptAtHwTen<Newmark>();
}

// Modified Newton (the factor kept across iterations and steps) reaches the same converged
// steps as plain Newton, to the tolerance, with fewer factorizations.
TEST(NewtonIntegrators, ReusingTheFactorGivesTheSameConvergedSteps) {
  // jello.w's deformed, fast-moving cube at 8^3, free of walls and plane (a contact's kink can
  // keep even plain Newton from its tolerance, which would compare nothing), at h = 0.002: at
  // 0.01 midpoint's equations have several solutions on this cube, and the two iterations were
  // measured converging to different ones, 0.25 m apart.
  const World w = test::loadWorld("jello.w");
  const ModelSpec free = test::freeCube(w);
  for (IntegratorKind kind : test::kConverged) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    ImplicitOptions plain, reuse;
    plain.reuseFactor = false;
    plain.newtonTolerance = reuse.newtonTolerance = 1e-10;
    plain.newtonPositionTolerance = reuse.newtonPositionTolerance = 1e-12;
    plain.newtonMaxIterations = reuse.newtonMaxIterations = 100;
    auto a = test::makeConverged(kind, plain), b = test::makeConverged(kind, reuse);
    const Model model(free);
    State sa = initialState(w), sb = sa;
    double worst = 0.0;
    for (int i = 0; i < 6; ++i) {
      ASSERT_TRUE(a->step(model, sa, 0.002).ok);
      ASSERT_TRUE(b->step(model, sb, 0.002).ok);
      ASSERT_TRUE(a->lastConverged() && b->lastConverged()) << "step " << i;
      worst = std::max(worst, (sa.x - sb.x).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, 1e-8);  // m: both within their tolerance of the same steps
    EXPECT_LT(b->linearSolver().stats().factorizations, a->linearSolver().stats().factorizations);
  }
}

// Seeds with Chebyshev acceleration down to Newton's tolerance: the fastest configuration
// (solvers/README.md).
ImplicitOptions chebyshevSeeded() {
  ImplicitOptions o;
  o.linearSolver = LinearSolverKind::Cg;
  o.preconditioner = PreconditionerKind::Projective;
  o.seedIterations = 60;
  o.seedTolerance = o.newtonTolerance;
  o.seedChebyshevRho = 0.9;
  return o;
}

// Seeding Newton with projective iterations (and solving by CG preconditioned by the projective
// matrix), plain or with Chebyshev acceleration, changes where Newton starts, not where it ends:
// the same converged steps, to the tolerance, on the fast-moving free cube, with fewer Newton
// iterations for backward Euler.
TEST(NewtonIntegrators, SeedingWithProjectiveIterationsGivesTheSameConvergedSteps) {
  const World w = test::loadWorld("jello.w");
  const ModelSpec free = test::freeCube(w);
  for (IntegratorKind kind : test::kConverged) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    ImplicitOptions plain, seeded;
    plain.newtonTolerance = seeded.newtonTolerance = 1e-10;
    plain.newtonPositionTolerance = seeded.newtonPositionTolerance = 1e-12;
    plain.newtonMaxIterations = seeded.newtonMaxIterations = 100;
    seeded.seedIterations = 30;
    seeded.linearSolver = LinearSolverKind::Cg;
    seeded.preconditioner = PreconditionerKind::Projective;
    seeded.cgTolerance = 1e-12;
    ImplicitOptions chebyshev = chebyshevSeeded();
    chebyshev.newtonTolerance = chebyshev.seedTolerance = 1e-10;
    chebyshev.newtonPositionTolerance = 1e-12;
    chebyshev.newtonMaxIterations = 100;
    chebyshev.cgTolerance = 1e-12;
    auto a = test::makeConverged(kind, plain), b = test::makeConverged(kind, seeded),
         c = test::makeConverged(kind, chebyshev);
    const Model model(free);
    State sa = initialState(w), sb = sa, sc = sa;
    double worst = 0.0;
    for (int i = 0; i < 6; ++i) {
      ASSERT_TRUE(a->step(model, sa, 0.002).ok);
      ASSERT_TRUE(b->step(model, sb, 0.002).ok);
      ASSERT_TRUE(c->step(model, sc, 0.002).ok);
      ASSERT_TRUE(a->lastConverged() && b->lastConverged() && c->lastConverged()) << "step " << i;
      worst = std::max(
          {worst, (sa.x - sb.x).cwiseAbs().maxCoeff(), (sa.x - sc.x).cwiseAbs().maxCoeff()});
    }
    EXPECT_LE(worst, 1e-8);  // m
    double seeds = 0.0, newtonA = 0.0, newtonB = 0.0;
    for (const Statistic& s : b->statistics()) {
      if (s.name == "seed_iterations") seeds = s.value;
      if (s.name == "newton_iterations") newtonB = s.value;
    }
    for (const Statistic& s : a->statistics()) {
      if (s.name == "newton_iterations") newtonA = s.value;
    }
    EXPECT_GT(seeds, 0.0);
    // Measured 80 -> 63 (implicit), 85 -> 51 (midpoint), 80 -> 50 (newmark), 76 -> 45 (bdf2).
    EXPECT_LT(newtonB, newtonA);
    std::printf("%s: Newton iterations %g plain, %g after %g seed iterations\n",
                std::string(integratorName(kind)).c_str(), newtonA, newtonB, seeds);
  }
}

// Through contact: jello.w's cube (without its plane) pressed 1 cm into the floor (smooth
// contact), three steps from states in contact. Its contacts are light against the points' springs,
// so the seeds go on through them, corrected on a coarse lattice (ImplicitSystem::lightContactsAt;
// before, they stopped at the first iterate in contact and did nothing here): the same converged
// steps, fewer Newton iterations.
TEST(NewtonIntegrators, SeedsGoOnThroughLightContacts) {
  World w = test::loadWorld("jello.w");
  w.contact.model = ContactModel::Smooth;
  w.contact.layer = kDefaultContactLayer;
  w.plane.reset();  // the floor alone
  const Model model(w);
  State start = initialState(w);
  const int n = start.numPoints();
  const double lowest = start.x.segment(2 * n, n).minCoeff();
  for (int p = 0; p < n; ++p) {
    start.x[2 * n + p] += -2.01 - lowest;
    start.v[2 * n + p] = -1.0;
  }
  ASSERT_TRUE(model.inContact(start.x.data()));
  for (IntegratorKind kind : {IntegratorKind::Implicit, IntegratorKind::Bdf2}) {
    SCOPED_TRACE(std::string(integratorName(kind)));
    ImplicitOptions plain;
    plain.newtonTolerance = 1e-10;
    plain.newtonPositionTolerance = 1e-12;
    plain.newtonMaxIterations = 100;
    ImplicitOptions seeded = chebyshevSeeded();
    seeded.newtonTolerance = seeded.seedTolerance = 1e-10;
    seeded.newtonPositionTolerance = 1e-12;
    seeded.newtonMaxIterations = 100;
    seeded.cgTolerance = 1e-12;
    auto a = test::makeConverged(kind, plain), b = test::makeConverged(kind, seeded);
    State sa = start, sb = start;
    double worst = 0.0;
    for (int i = 0; i < 3; ++i) {  // each from a state in contact
      ASSERT_TRUE(model.inContact(sb.x.data())) << "step " << i;
      ASSERT_TRUE(a->step(model, sa, 0.01).ok);
      ASSERT_TRUE(b->step(model, sb, 0.01).ok);
      ASSERT_TRUE(a->lastConverged() && b->lastConverged()) << "step " << i;
      worst = std::max(worst, (sa.x - sb.x).cwiseAbs().maxCoeff());
    }
    EXPECT_LE(worst, 1e-8);  // m
    std::map<std::string, double> stats, plainStats;
    for (const Statistic& s : b->statistics()) stats[s.name] = s.value;
    for (const Statistic& s : a->statistics()) plainStats[s.name] = s.value;
    // Shown for solvers/README.md's figures; asserted below (at most half of plain Newton's).
    std::printf("%s in contact: Newton iterations %g plain, %g after %g seed iterations\n",
                std::string(integratorName(kind)).c_str(), plainStats.at("newton_iterations"),
                stats.at("newton_iterations"), stats.at("seed_iterations"));
    EXPECT_GE(stats.at("seed_iterations"), 30.0);
    EXPECT_LT(2.0 * stats.at("newton_iterations"), plainStats.at("newton_iterations"));
  }
}

// Clamped, Newton's matrix is not the residual's derivative where springs are compressed, and
// Newton converges only linearly there; on demand (ImplicitOptions::clampOnDemand) it solves with
// the exact Jacobian and clamps only where that fails. jello.w thrown into the walls with smooth
// contact, 30 steps of backward Euler in the fast configuration (seeded, CG with the projective
// preconditioner, plain Newton): the same converged steps with fewer Newton iterations. With
// CG's Jacobi preconditioner the exact system's diagonal turns negative in step 7 (the clamp off,
// the run stops there): on demand, that update is solved clamped, counted, and the run goes on.
TEST(NewtonIntegrators, ClampOnDemandTakesTheSameStepsInFewerIterationsAndClampsWhereItMust) {
  World w = test::loadWorld("jello.w");
  w.contact = {ContactModel::Smooth, kDefaultContactLayer};
  const Model model(w);
  const auto run = [&](ImplicitOptions o, int steps, std::map<std::string, double>& stats) {
    o.reuseFactor = false;
    BackwardEuler be(o);
    State s = initialState(w);
    for (int i = 0; i < steps; ++i) {
      const StepResult r = be.step(model, s, 0.01);
      EXPECT_TRUE(r.ok && be.lastConverged()) << "step " << i << ": " << r.message;
      if (!r.ok) break;
    }
    for (const Statistic& st : be.statistics()) stats[st.name] = st.value;
    return s;
  };
  ImplicitOptions fast = chebyshevSeeded();
  std::map<std::string, double> clamped, exact;
  const State a = run(fast, 30, clamped);
  fast.clampOnDemand = true;
  const State b = run(fast, 30, exact);
  EXPECT_LE((a.x - b.x).cwiseAbs().maxCoeff(), 1e-6);  // m, after a 1.8 m throw
  EXPECT_EQ(exact.at("clamp_fallbacks"), 0.0);
  EXPECT_LT(1.5 * exact.at("newton_iterations"), clamped.at("newton_iterations"));

  ImplicitOptions jacobi;
  jacobi.clampOnDemand = true;
  std::map<std::string, double> stats;
  run(jacobi, 10, stats);
  EXPECT_GE(stats.at("clamp_fallbacks"), 1.0);
  EXPECT_GT(stats.at("compression_clamps"), 0.0);
}

// For backward Euler the Chebyshev seeds converge the steps themselves: on the spinning
// stretched stiff cube at h = 0.01, once the first steps are past, no Newton iteration at all
// (measured: the first 6 steps take 11 undamped, the next 14 none), and every step satisfies
// backward Euler's equations, checked from the states (converged by the residual alone here: a
// stiff cube's Newton update falls below the default 1e-8 m while its residual is still 1e-5
// relative).
TEST(NewtonIntegrators, ChebyshevSeedsConvergeBackwardEulerStepsThemselves) {
  for (double damping : {0.0, 0.25}) {
    SCOPED_TRACE("damping " + std::to_string(damping));
    SceneSpec spec = vibratingStiffCube(1e4);
    spec.dElastic = damping;
    const World w = buildWorld(spec);
    const Model model(w);
    ImplicitOptions o = chebyshevSeeded();
    o.newtonPositionTolerance = 1e-15;
    auto method = test::makeConverged(IntegratorKind::Implicit, o);
    State s = initialState(w);
    const double h = 0.01;
    const int steps = 20;
    int lateNewton = 0;  // Newton iterations of the second half's steps
    for (int i = 0; i < steps; ++i) {
      const State before = s;
      ASSERT_TRUE(method->step(model, s, h).ok);
      ASSERT_TRUE(method->lastConverged()) << "step " << i;
      Eigen::VectorXd f;
      model.forces(s.x, s.v, f);
      const double scale = model.mass() * (s.v - before.v).norm() / h + f.norm();
      const Eigen::VectorXd r =
          methodResidual(IntegratorKind::Implicit, model, before, before, s, h, false);
      EXPECT_LE(r.norm(), 3e-8 * scale) << "step " << i;
      if (2 * i >= steps) lateNewton += method->lastIterations();
    }
    double seeds = 0.0, newton = 0.0;
    for (const Statistic& st : method->statistics()) {
      if (st.name == "seed_iterations") seeds = st.value;
      if (st.name == "newton_iterations") newton = st.value;
    }
    std::printf(
        "damping %.2f: %g seed and %g Newton iterations over %d steps (%d in the second "
        "half)\n",
        damping, seeds, newton, steps, lateNewton);
    EXPECT_EQ(lateNewton, 0);
  }
}

}  // namespace
}  // namespace jello
