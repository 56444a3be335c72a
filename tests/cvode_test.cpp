// CVODE: accuracy against RK4, its options, and continuing across outside changes.
#include <gtest/gtest.h>

#include <map>

#include "solvers/cvode_integrator.h"
#include "solvers/explicit_integrators.h"
#include "solvers/simulation.h"
#include "tests/test_support.h"

namespace jello {
namespace {

std::map<std::string, double> statsOf(const Integrator& integrator) {
  std::map<std::string, double> m;
  for (const Statistic& s : integrator.statistics()) m[s.name] = s.value;
  return m;
}

TEST(Cvode, AtTightToleranceMatchesRK4OnJelloToAMicrometre) {
  const World w = test::loadWorld("jello.w");
  const Model model(w);
  State ref = initialState(w);
  RungeKutta4 rk4;
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(rk4.step(model, ref, 1e-5).ok);

  CvodeOptions options;
  options.rtol = 1e-8;
  CvodeIntegrator cvode(options);
  State s = initialState(w);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(cvode.step(model, s, 1e-3).ok);  // 10 outputs
  EXPECT_NEAR(s.t, 0.01, 1e-15);
  EXPECT_LT((s.x - ref.x).cwiseAbs().maxCoeff(), 1e-6);

  const auto stats = statsOf(cvode);
  EXPECT_GT(stats.at("cvode_steps"), 10);
  EXPECT_GE(stats.at("rhs_evaluations"), stats.at("cvode_steps"));
  EXPECT_GT(stats.at("linear_setups"), 0);
  EXPECT_GE(stats.at("newton_iterations"), stats.at("cvode_steps"));
  EXPECT_GE(stats.at("last_order"), 1);
}

TEST(Cvode, RespectsTheMaximumOrder) {
  const World w = test::loadWorld("moveLeft.w");
  const Model model(w);
  CvodeOptions options;
  options.rtol = 1e-4;
  options.maxOrder = 2;
  options.linearSolver = LinearSolverKind::Cg;
  CvodeIntegrator cvode(options);
  State s = initialState(w);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(cvode.step(model, s, 2e-3).ok);
  EXPECT_LE(statsOf(cvode).at("last_order"), 2);
}

TEST(Cvode, ContinuesCorrectlyAfterTheStateIsChangedFromOutside) {
  // Switching integrators mid-run hands CVODE a state it did not produce: it must restart
  // from it rather than continue its own history.
  Simulation a(test::loadWorld("jello.w"), IntegratorKind::Cvode, 1e-3);
  Simulation b(test::loadWorld("jello.w"), IntegratorKind::RK4, 1e-5);
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(a.step().ok);
  a.setIntegrator(IntegratorKind::RK4);
  a.setTimeStep(1e-5);
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(a.step().ok);
  a.setIntegrator(IntegratorKind::Cvode);
  a.setTimeStep(1e-3);
  for (int i = 0; i < 2; ++i) ASSERT_TRUE(a.step().ok);
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(b.step().ok);
  EXPECT_NEAR(a.state().t, b.state().t, 1e-12);
  EXPECT_LT((a.state().x - b.state().x).cwiseAbs().maxCoeff(), 1e-4);
}

}  // namespace
}  // namespace jello
