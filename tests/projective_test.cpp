// projective (solvers/methods/projective_integrator.h): its iterations converge to the
// backward-Euler step, it keeps what backward Euler keeps, its factor is reused, and contact
// changes refactor.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <map>
#include <vector>

#include "solvers/methods/newton_integrators.h"
#include "solvers/methods/projective_integrator.h"
#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

using test::angularMomentum;
using test::backwardEulerStep;

State projectiveStep(const Model& model, const State& start, double h, int iterations,
                     double chebyshevRho = 0.0, ProjectiveOptions o = {}) {
  o.iterations = iterations;
  o.chebyshevRho = chebyshevRho;
  ProjectiveIntegrator pd(o);
  State s = start;
  EXPECT_TRUE(pd.step(model, s, h).ok);
  // Every iteration is done, unless one reached the fixed point exactly (an update of 0 stops
  // them at the default tolerance 0: Chebyshev through contact did at 75 of 300 under ASan).
  // With a tolerance, the iterations reach it.
  if (o.tolerance > 0.0) {
    EXPECT_LE(pd.lastUpdate(), o.tolerance);
    return s;
  }
  EXPECT_TRUE(pd.lastIterations() == iterations || pd.lastUpdate() == 0.0)
      << pd.lastIterations() << " of " << iterations << " iterations, the last moving "
      << pd.lastUpdate() << " m";
  return s;
}

// |x_projective - x_BE| / |x_BE - x0|: the step's error relative to the step.
double relativeStepError(const State& start, const State& be, const State& pd) {
  return (pd.x - be.x).norm() / (be.x - start.x).norm();
}

// w's cube thrown straight down at `speed` m/s, toward the floor z = -2.
State thrownDown(const World& w, double speed) {
  State s = initialState(w);
  const int n = s.numPoints();
  for (int p = 0; p < n; ++p) s.v[2 * n + p] = -speed;
  return s;
}

// `steps` steps of pd from s at h = 0.01: the deepest any point went below the floor (m).
double stepOverTheFloor(Integrator& pd, const Model& model, State& s, int steps) {
  const int n = s.numPoints();
  double deepest = 0.0;
  for (int i = 0; i < steps; ++i) {
    if (!pd.step(model, s, 0.01).ok) {
      ADD_FAILURE() << "step " << i << " failed";
      return std::numeric_limits<double>::infinity();
    }
    deepest = std::max(deepest, -2.0 - s.x.segment(2 * n, n).minCoeff());
  }
  return deepest;
}

std::map<std::string, double> statisticsOf(const Integrator& pd) {
  std::map<std::string, double> stats;
  for (const Statistic& st : pd.statistics()) stats[st.name] = st.value;
  return stats;
}

World spinningCube(double k, double damping) {
  SceneSpec spec = vibratingStiffCube(k);
  spec.dElastic = damping;
  return buildWorld(spec);
}

// jello.w's deformed cube shifted so some points are through the x = -2 wall, and thrown down
// (toward the plane): contact, contact damping and spring damping in one step.
State throughAWall(const World& w) {
  State start = initialState(w);
  const int n = start.numPoints();
  for (int p = 0; p < n; ++p) start.x[p] -= 0.35;
  for (int p = 0; p < n; ++p) start.v[2 * n + p] -= 3.0;
  return start;
}

// jello.w through a wall (throughAWall) and backward Euler's step from there, h = 0.01.
struct ThroughAWallStep {
  World w = test::loadWorld("jello.w");
  Model model{w};
  State start = throughAWall(w);
  State be = backwardEulerStep(model, start, 0.01);
};

TEST(Projective, ConvergesToTheBackwardEulerStepAsIterationsGrow) {
  for (double damping : {0.0, 0.25}) {
    SCOPED_TRACE("damping " + std::to_string(damping));
    const World w = spinningCube(1e4, damping);
    const Model model(w);
    const State start = initialState(w);
    const State be = backwardEulerStep(model, start, 0.01);
    double previous = 1e300;
    for (int iterations : {1, 2, 5, 10, 20, 50, 200}) {
      const double e = relativeStepError(start, be, projectiveStep(model, start, 0.01, iterations));
      std::printf("damping %.2f, %3d iterations: step within %.3g of backward Euler's\n", damping,
                  iterations, e);
      EXPECT_LT(e, previous) << iterations << " iterations";
      previous = e;
      if (iterations == 10) {
        EXPECT_LE(e, 0.005);
      }
    }
    // 200 iterations: the same step (measured 5e-14 undamped; the damping, lagged one
    // iteration, slows the last digits: 4e-7).
    EXPECT_LE(previous, damping == 0.0 ? 1e-10 : 1e-6);
  }
}

// At 16^3 the factor is solved over its single-precision supernodes (PrefactoredCholesky): an
// inexact global step changes how fast the iterations approach backward Euler's step, not the
// step they approach (the residual they drive to zero is evaluated in double).
TEST(Projective, ConvergesAsFarWithTheSinglePrecisionFactor) {
  const World w = resampleCube(spinningCube(1e4, 0.0), 16);
  const Model model(w);
  const State start = initialState(w);
  const State be = backwardEulerStep(model, start, 0.01);
  const double ten = relativeStepError(start, be, projectiveStep(model, start, 0.01, 10));
  const double many = relativeStepError(start, be, projectiveStep(model, start, 0.01, 200));
  std::printf("16^3: 10 iterations within %.3g of backward Euler's step, 200 within %.3g\n", ten,
              many);
  EXPECT_LE(ten, 0.005);
  EXPECT_LE(many, 1e-9);  // measured 4e-11
}

// Chebyshev acceleration (Wang 2015, rho = 0.85) reaches the same step in fewer iterations:
// measured on the spinning cube, 3.8x closer than the plain iterations at 10, 50x at 20, where
// it is as close as 50 plain ones (within 3%); it converges as far.
TEST(Projective, ChebyshevReachesTheBackwardEulerStepInFewerIterations) {
  for (double k : {1e4, 1e5}) {
    for (double damping : {0.0, 0.25}) {
      SCOPED_TRACE("k " + std::to_string(k) + ", damping " + std::to_string(damping));
      const World w = spinningCube(k, damping);
      const Model model(w);
      const State start = initialState(w);
      const State be = backwardEulerStep(model, start, 0.01);
      std::map<int, double> plain, fast;
      for (int iterations : {10, 20, 50, 200}) {
        plain[iterations] =
            relativeStepError(start, be, projectiveStep(model, start, 0.01, iterations));
        fast[iterations] =
            relativeStepError(start, be, projectiveStep(model, start, 0.01, iterations, 0.85));
        std::printf("k %g, damping %.2f, %3d iterations: plain %.3g, Chebyshev %.3g\n", k, damping,
                    iterations, plain[iterations], fast[iterations]);
      }
      EXPECT_LT(fast[10], plain[10] / 2.0);
      EXPECT_LT(fast[20], plain[20] / 10.0);
      EXPECT_LT(fast[20], 1.1 * plain[50]);
      EXPECT_LE(fast[200], damping == 0.0 ? 1e-10 : 1e-6);
    }
  }
}

// Through contact (the walls and the plane, contact damping): Chebyshev converges to the same
// backward-Euler step.
TEST(Projective, ChebyshevConvergesThroughContact) {
  const ThroughAWallStep step;
  const Model& model = step.model;
  const State &start = step.start, &be = step.be;
  const double plain = relativeStepError(start, be, projectiveStep(model, start, 0.01, 30));
  const double fast = relativeStepError(start, be, projectiveStep(model, start, 0.01, 30, 0.85));
  std::printf("jello.w through a wall, 30 iterations: plain %.3g, Chebyshev %.3g\n", plain, fast);
  EXPECT_LT(fast, plain);
  EXPECT_LE(relativeStepError(start, be, projectiveStep(model, start, 0.01, 300, 0.85)), 1e-7);
}

TEST(Projective, ConvergesToTheBackwardEulerStepThroughContact) {
  // jello.w's deformed cube against the walls and the plane, with damping and contact damping:
  // the fixed point is backward Euler's with every effect where it evaluates them.
  const ThroughAWallStep step;
  const Model& model = step.model;
  const State &start = step.start, &be = step.be;
  const double e = relativeStepError(start, be, projectiveStep(model, start, 0.01, 300));
  EXPECT_LE(e, 1e-7);
}

TEST(Projective, KeepsTheAngularMomentumLikeBackwardEuler) {
  // The spinning, stretched stiff cube, undamped, 0.2 s at h = 0.01.
  for (double k : {1e4, 1e5}) {
    SCOPED_TRACE("k " + std::to_string(k));
    const World w = spinningCube(k, 0.0);
    // implicit, projective, projective with Chebyshev (rho 0.85).
    double kept[3], energy[3];
    for (int i = 0; i < 3; ++i) {
      SolverOptions o;
      if (i == 2) o.projective.chebyshevRho = 0.85;
      Simulation sim(w, i == 0 ? IntegratorKind::Implicit : IntegratorKind::Projective, 0.01, o);
      const Eigen::Vector3d L0 = angularMomentum(sim.model(), sim.state());
      const double e0 = sim.model().energy(sim.state()).total();
      for (int step = 0; step < 20; ++step) ASSERT_TRUE(sim.step().ok);
      kept[i] = angularMomentum(sim.model(), sim.state()).dot(L0) / L0.squaredNorm();
      energy[i] = sim.model().energy(sim.state()).total() / e0;
    }
    std::printf(
        "k = %g: implicit keeps %.4f of the angular momentum and %.4g of the energy, "
        "projective %.4f and %.4g, with Chebyshev %.4f and %.4g\n",
        k, kept[0], energy[0], kept[1], energy[1], kept[2], energy[2]);
    EXPECT_NEAR(kept[1], kept[0], 0.01);
    // Chebyshev converges to the same step: the same angular momentum and energy as implicit.
    EXPECT_NEAR(kept[2], kept[0], 0.01);
    EXPECT_NEAR(energy[2], energy[0], 0.05 * energy[0] + 1e-6);
  }
}

TEST(Projective, FactorsOncePerSceneAndStepSizeAndAgainOnContactChanges) {
  const World free = spinningCube(1e4, 0.25);
  const Model model(free);
  ProjectiveIntegrator pd;
  State s = initialState(free);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(pd.step(model, s, 0.01).ok);
  EXPECT_EQ(pd.refactorizations(), 1);  // three coordinates, one shared factor
  ASSERT_TRUE(pd.step(model, s, 0.005).ok);
  EXPECT_EQ(pd.refactorizations(), 2);  // a new h
  // Another model (even at the same address) is bound afresh.
  Model other(free);
  ASSERT_TRUE(pd.step(other, s, 0.005).ok);
  EXPECT_EQ(pd.refactorizations(), 3);

  // Thrown onto the floor: the contact set changes, and each change refactors when the factor
  // follows every contact (without the coarse correction: the path of contacts too stiff for it).
  World w = test::loadWorld("jello.w");
  const Model wall(w);
  ProjectiveOptions exact;
  exact.coarseNodes = 0;
  ProjectiveIntegrator thrown(exact);
  State t = thrownDown(w, 20.0);
  const double deepest = stepOverTheFloor(thrown, wall, t, 30);
  EXPECT_GT(thrown.refactorizations(), 1);
  EXPECT_LT(deepest, 0.05);  // the penalty holds it within 5 cm
  double changes = -1.0, updates = -1.0;
  for (const Statistic& st : thrown.statistics()) {
    if (st.name == "contact_set_changes") changes = st.value;
    if (st.name == "factor_updates") updates = st.value;
  }
  EXPECT_GE(changes, 1.0);
  // Most changes are a few points: rank-one updates of the factor (cholmod_updown), which take
  // the same steps as factoring afresh every time, to round-off.
  EXPECT_GE(updates, 1.0);
  ProjectiveOptions refactorOnly = exact;
  refactorOnly.updateFactors = false;
  ProjectiveIntegrator fresh(refactorOnly);
  State u = thrownDown(w, 20.0);
  (void)stepOverTheFloor(fresh, wall, u, 30);
  EXPECT_LT((u.x - t.x).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GT(fresh.refactorizations(), thrown.refactorizations());
}

// The contact weights cover the contacts (planned at the step's start a step ahead, kept after
// a point leaves) instead of following the iterate's exactly: the same backward-Euler steps,
// the residual being exact, for far fewer changes of the factor. Smooth contact: the penalty's
// kink leaves some steps unconverged either way.
TEST(Projective, CoveringContactWeightsTakeTheSameStepsWithFewerFactorChanges) {
  World w = test::loadWorld("jello.w");
  w.contact.model = ContactModel::Smooth;
  w.contact.layer = kDefaultContactLayer;
  const Model model(w);
  const auto thrown = [&](bool cover, std::map<std::string, double>* stats) {
    ProjectiveOptions options;
    options.iterations = 2000;
    options.tolerance = 1e-11;
    options.coverContacts = cover;
    options.coarseNodes = 0;  // the factor alone covers or follows the contacts
    ProjectiveIntegrator pd(options);
    State s = initialState(w);
    const int n = s.numPoints();
    for (int p = 0; p < n; ++p) s.v[2 * n + p] = -20.0;
    for (int i = 0; i < 30; ++i) {
      EXPECT_TRUE(pd.step(model, s, 0.01).ok);
      EXPECT_LE(pd.lastUpdate(), options.tolerance);  // converged
    }
    for (const Statistic& st : pd.statistics()) (*stats)[st.name] = st.value;
    return s;
  };
  std::map<std::string, double> covering, exact;
  const State a = thrown(true, &covering), b = thrown(false, &exact);
  const double changesA = covering.at("factorizations") + covering.at("factor_updates");
  const double changesB = exact.at("factorizations") + exact.at("factor_updates");
  const double apart = (a.x - b.x).cwiseAbs().maxCoeff();
  // Shown for the README's figures; asserted below.
  std::printf("thrown at the floor: %g factor changes covering, %g exact, %.3g m apart\n", changesA,
              changesB, apart);
  EXPECT_LT(changesA, changesB / 2.0);
  EXPECT_LT(apart, 1e-7);
  const int n = a.numPoints();
  EXPECT_GT(a.x.segment(2 * n, n).minCoeff(), -2.05);  // the floor holds
}

// jello.w's contacts are light: kc = 400 N/m against a point's diagonal of m/h^2 and its
// springs' stiffness (about 2,000 to 5,000 N/m at h = 0.01). The factor stays that of
// M/h^2 + L, each global solve is corrected on 4^3 coarse nodes (solvers/system/
// lattice_coarse_space.h), and the steps are backward Euler's as before: iterated to the fixed
// point, the same steps as a factor that follows every contact; at ten iterations as close to
// backward Euler as it.
TEST(Projective, LightContactsLeaveTheFactorToTheCoarseCorrection) {
  // Smooth contact: the penalty's kink leaves some steps unconverged either way.
  World w = test::loadWorld("jello.w");
  w.contact.model = ContactModel::Smooth;
  w.contact.layer = kDefaultContactLayer;
  const Model model(w);
  const auto thrown = [&](ProjectiveOptions o, std::map<std::string, double>* stats,
                          double* deepest) {
    ProjectiveIntegrator pd(o);
    State s = thrownDown(w, 20.0);
    *deepest = stepOverTheFloor(pd, model, s, 30);
    *stats = statisticsOf(pd);
    return s;
  };
  std::map<std::string, double> stats, exactStats;
  double deepest = 0.0, deepestExact = 0.0;
  ProjectiveOptions converged;
  converged.iterations = 3000;
  converged.tolerance = 1e-12;
  ProjectiveOptions convergedExact = converged;
  convergedExact.coarseNodes = 0;
  const State a = thrown(converged, &stats, &deepest);
  const State b = thrown(convergedExact, &exactStats, &deepestExact);
  const double moved = (a.x - initialState(w).x).cwiseAbs().maxCoeff();
  const double apart = (a.x - b.x).cwiseAbs().maxCoeff();
  // Shown for solvers/README.md; asserted below.
  std::printf(
      "thrown at the floor, converged: %.3g m apart after moving %.3g m; %g corrected "
      "solves\n",
      apart, moved, stats.at("coarse_corrections"));
  EXPECT_LT(apart, 1e-8 * moved);
  EXPECT_EQ(stats.at("factorizations"), 1.0);
  EXPECT_EQ(stats.at("factor_updates"), 0.0);
  EXPECT_EQ(stats.at("contact_set_changes"), 0.0);
  EXPECT_GT(stats.at("coarse_corrections"), 30.0);
  EXPECT_GT(exactStats.at("factor_updates") + exactStats.at("factorizations"), 10.0);
  // Ten iterations: the floor holds it as well.
  stats.clear();
  deepest = 0.0;
  (void)thrown(ProjectiveOptions{}, &stats, &deepest);
  EXPECT_EQ(stats.at("factorizations"), 1.0);
  EXPECT_LT(deepest, 0.05);
  // And each step of ten iterations is as close to the fixed point as with the factor following
  // every contact: from each state of the throw, the error relative to the step.
  ProjectiveOptions following;
  following.coarseNodes = 0;
  ProjectiveIntegrator driver;
  State s = thrownDown(w, 20.0);
  double worst[2] = {0.0, 0.0}, sum[2] = {0.0, 0.0};
  for (int i = 0; i < 30; ++i) {
    const State fixedPoint = projectiveStep(model, s, 0.01, 3000, 0.0, convergedExact);
    for (int k = 0; k < 2; ++k) {
      const State t = projectiveStep(model, s, 0.01, 10, 0.0, k ? following : ProjectiveOptions{});
      const double e = relativeStepError(s, fixedPoint, t);
      worst[k] = std::max(worst[k], e);
      sum[k] += e;
    }
    ASSERT_TRUE(driver.step(model, s, 0.01).ok);
  }
  // Shown for solvers/README.md; asserted below (within 10% of the following factor's).
  std::printf(
      "10 iterations from each state of the throw: worst %.4g, mean %.4g of the step "
      "(following every contact: %.4g, %.4g)\n",
      worst[0], sum[0] / 30, worst[1], sum[1] / 30);
  EXPECT_LE(worst[0], 1.1 * worst[1]);
  EXPECT_LE(sum[0], 1.1 * sum[1]);
}

// Contact as stiff as kc = 1e5 N/m outweighs a point's diagonal: such weights go into the factor
// (updates or a new factorization) and the coarse correction takes only the light ones.
TEST(Projective, HeavyContactsStillEnterTheFactor) {
  World w = test::loadWorld("jello.w");
  w.kCollision = 1e5;
  const Model model(w);
  ProjectiveIntegrator pd;
  State s = thrownDown(w, 5.0);
  const double deepest = stepOverTheFloor(pd, model, s, 30);
  const std::map<std::string, double> stats = statisticsOf(pd);
  EXPECT_GE(stats.at("contact_set_changes"), 1.0);
  EXPECT_GE(stats.at("factor_updates") + stats.at("factorizations"), 2.0);
  EXPECT_LT(deepest, 0.01);
}

// At 10^3 points and up the factor is solved in single precision and contact changes become a
// low-rank correction through it (solvers/linalg/diagonal_correction.h) instead of CHOLMOD's
// updates: the same steps as factoring afresh at every change, to the factor's precision, and the
// floor still holds the cube.
TEST(Projective, LargeFactorsTakeContactChangesAsACorrectionWithTheSameSteps) {
  const World w = resampleCube(test::loadWorld("jello.w"), 12);
  const Model model(w);
  const auto thrownAtTheFloor = [&](const ProjectiveOptions& options, double* deepest) {
    ProjectiveIntegrator pd(options);
    State s = thrownDown(w, 20.0);
    *deepest = stepOverTheFloor(pd, model, s, 20);
    return std::make_pair(s, statisticsOf(pd));
  };
  // Iterated close to the fixed point, which the factor does not change (residuals in double):
  // ten iterations would magnify the two factors' rounding into the iterates.
  ProjectiveOptions converged;
  converged.iterations = 60;
  converged.chebyshevRho = 0.85;
  converged.tolerance = 1e-11;
  converged.coarseNodes = 0;  // every contact change goes to the factor
  double deepest = 0.0, deepestFresh = 0.0;
  const auto [corrected, stats] = thrownAtTheFloor(converged, &deepest);
  ProjectiveOptions refactorOnly = converged;
  refactorOnly.updateFactors = false;
  const auto [fresh, freshStats] = thrownAtTheFloor(refactorOnly, &deepestFresh);
  EXPECT_GE(stats.at("factor_updates"), 3.0);
  EXPECT_LT(stats.at("factorizations"), freshStats.at("factorizations"));
  const double moved = (corrected.x - initialState(w).x).cwiseAbs().maxCoeff();
  const double apart = (corrected.x - fresh.x).cwiseAbs().maxCoeff();
  std::printf(
      "12^3 thrown at the floor: %g updates, %g against %g factorizations, moved %.3g m, "
      "%.3g m from refactoring\n",
      stats.at("factor_updates"), stats.at("factorizations"), freshStats.at("factorizations"),
      moved, apart);
  EXPECT_LT(apart, 2e-8 * moved);  // measured 4e-9
  EXPECT_LT(deepest, 0.05);
}

}  // namespace
}  // namespace jello
