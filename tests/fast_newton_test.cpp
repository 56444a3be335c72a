// The converged Newton methods' fast configuration (ImplicitOptions::fast(): a few Chebyshev
// seeds, plain Newton on the exact Jacobian with A filled straight from the springs, each update
// solved inexactly by CG): it changes what a step costs, never which step is taken. Checked on
// jello.w thrown into the walls with smooth contact, against plain Newton solved exactly by
// CHOLMOD, and through each step's own equations written out from the states.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "solvers/methods/newton_integrators.h"
#include "src/world/scene_builder.h"
#include "tests/newton_test_support.h"
#include "tests/test_support.h"

namespace jello {
namespace {

struct Steps {
  State state;
  std::map<std::string, double> stats;
  double worstResidual = 0.0;  // of backward Euler's equations, relative to the step's forces
};

// 30 steps of backward Euler at h = 0.01 from jello.w's start (its cube reaches the walls).
Steps thirtySteps(const World& w, const ImplicitOptions& o) {
  const Model model(w);
  BackwardEuler be(o);
  Steps run{initialState(w), {}, 0.0};
  State& s = run.state;
  const double h = 0.01;
  Eigen::VectorXd f;
  for (int i = 0; i < 30; ++i) {
    const State before = s;
    const StepResult r = be.step(model, s, h);
    EXPECT_TRUE(r.ok && be.lastConverged()) << "step " << i << ": " << r.message;
    if (!r.ok) break;
    // x1 = x0 + h v1 and m (v1 - v0)/h = f(x1, v1), from the states alone.
    EXPECT_LE((s.x - before.x - h * s.v).cwiseAbs().maxCoeff(), 1e-12);
    model.forces(s.x, s.v, f);
    const Eigen::VectorXd inertia = model.mass() * (s.v - before.v) / h;
    run.worstResidual =
        std::max(run.worstResidual, (inertia - f).norm() / (inertia.norm() + f.norm()));
  }
  for (const Statistic& st : be.statistics()) run.stats[st.name] = st.value;
  return run;
}

TEST(FastNewton, TakesPlainNewtonsConvergedStepsThroughContact) {
  World w = test::loadWorld("jello.w");
  w.contact = {ContactModel::Smooth, kDefaultContactLayer};
  ImplicitOptions exact;
  exact.linearSolver = LinearSolverKind::Cholmod;
  exact.reuseFactor = false;
  const Steps reference = thirtySteps(w, exact);
  const Steps fast = thirtySteps(w, ImplicitOptions::fast());
  ImplicitOptions tight = ImplicitOptions::fast();
  tight.cgTolerance = 1e-6;
  const Steps solvedTightly = thirtySteps(w, tight);

  EXPECT_GT(reference.state.x.maxCoeff(), 1.9);  // m: the cube went out to the walls
  for (const Steps* run : {&reference, &fast, &solvedTightly}) {
    EXPECT_LE(run->worstResidual, 1e-6);  // Newton stops at 1e-8 of its own scale, or 1e-8 m
    EXPECT_LE((run->state.x - reference.state.x).cwiseAbs().maxCoeff(), 1e-6);  // m
  }
  // Inexact updates: fewer CG iterations in all, in no more than 1.5x the Newton iterations.
  EXPECT_LT(fast.stats.at("cg_iterations"), 0.6 * solvedTightly.stats.at("cg_iterations"));
  EXPECT_LE(fast.stats.at("newton_iterations"), 1.5 * solvedTightly.stats.at("newton_iterations"));
  EXPECT_LT(fast.stats.at("newton_iterations"), reference.stats.at("newton_iterations"));
}

// On demand, a CG solve of the unclamped system that meets negative curvature goes straight to
// the clamp: no LDLT of the indefinite matrix first (at 16^3 one cost seconds, then was thrown
// away). jello.w at 16^3 meets one in its first three steps.
TEST(FastNewton, NegativeCurvatureGoesStraightToTheClamp) {
  const World w = resampleCube(test::loadWorld("jello.w"), 16);
  const Model model(w);
  BackwardEuler be(ImplicitOptions::fast());
  State s = initialState(w);
  for (int i = 0; i < 3; ++i) {
    const StepResult r = be.step(model, s, 0.01);
    ASSERT_TRUE(r.ok) << "step " << i << ": " << r.message;
    EXPECT_TRUE(be.lastConverged()) << "step " << i;
  }
  std::map<std::string, double> stats;
  for (const Statistic& st : be.statistics()) stats[st.name] = st.value;
  EXPECT_GE(stats.at("clamp_fallbacks"), 1.0);
  EXPECT_EQ(stats.at("ldlt_fallbacks"), 0.0);
}

}  // namespace
}  // namespace jello
