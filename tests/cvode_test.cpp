// CVODE: accuracy against RK4, its options, and continuing across outside changes.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "solvers/cvode/cvode_integrator.h"
#include "solvers/methods/explicit_integrators.h"
#include "solvers/simulation.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

std::map<std::string, double> statsOf(const Integrator& integrator) {
  std::map<std::string, double> m;
  for (const Statistic& s : integrator.statistics()) m[s.name] = s.value;
  return m;
}

// jello.w after 0.01 s of RK4 at h = 1e-5: the reference both CVODE methods are held to.
State rk4Reference(const Model& model, const World& w) {
  State ref = initialState(w);
  RungeKutta4 rk4;
  for (int i = 0; i < 1000; ++i) EXPECT_TRUE(rk4.step(model, ref, 1e-5).ok);
  return ref;
}

TEST(Cvode, AtTightToleranceMatchesRK4OnJelloToAMicrometre) {
  const World w = test::loadWorld("jello.w");
  const Model model(w);
  const State ref = rk4Reference(model, w);

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

TEST(Cvode, AdamsMatchesRK4OnJelloAtItsTolerance) {
  // jello.w's first 0.01 s (no contact yet), Adams with fixed-point iterations.
  const World w = test::loadWorld("jello.w");
  const Model model(w);
  const State ref = rk4Reference(model, w);
  for (double rtol : {1e-5, 1e-8}) {
    CvodeOptions options;
    options.method = CvodeMethod::Adams;
    options.rtol = rtol;
    CvodeIntegrator cvode(options);
    State s = initialState(w);
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(cvode.step(model, s, 1e-3).ok);
    const double error = (s.x - ref.x).cwiseAbs().maxCoeff();
    // Positions of order 1 m: the global error within a few hundred times rtol.
    EXPECT_LT(error, 300 * rtol) << "rtol " << rtol;
    const auto stats = statsOf(cvode);
    EXPECT_EQ(stats.at("factorizations"), 0);  // no linear algebra
    EXPECT_EQ(stats.count("linear_setups") ? stats.at("linear_setups") : 0.0, 0.0);
  }
}

TEST(Cvode, SpgmrMatchesRK4OnJelloAtItsTolerance) {
  // The same 0.01 s with BDF's Newton systems solved by SPGMR (CVODE's difference-quotient
  // J v), preconditioned by the reduced system under CHOLMOD and under CG.
  const World w = test::loadWorld("jello.w");
  const Model model(w);
  const State ref = rk4Reference(model, w);
  for (LinearSolverKind solver : {LinearSolverKind::Cholmod, LinearSolverKind::Cg}) {
    for (double rtol : {1e-5, 1e-8}) {
      CvodeOptions options;
      options.krylov = true;
      options.linearSolver = solver;
      options.rtol = rtol;
      CvodeIntegrator cvode(options);
      State s = initialState(w);
      for (int i = 0; i < 10; ++i) ASSERT_TRUE(cvode.step(model, s, 1e-3).ok);
      EXPECT_LT((s.x - ref.x).cwiseAbs().maxCoeff(), 300 * rtol)
          << linearSolverName(solver) << ", rtol " << rtol;
      const auto stats = statsOf(cvode);
      EXPECT_GT(stats.at("linear_iterations"), 0);
      EXPECT_GT(stats.at("preconditioner_solves"), 0);
      // The factor is kept between CVODE's setups whenever CVODE allows it.
      EXPECT_LE(stats.at("factorizations"), stats.at("linear_setups"));
      EXPECT_EQ(stats.at("factorizations"), stats.at("preconditioner_setups"));
    }
  }
}

TEST(Cvode, SpgmrAgreesWithTheDirectSolveOnAStiffCube) {
  // A stiff, heavily damped cube (k = 1e5 N/m, c = 50 N*s/m: its fast modes decay at once, the
  // regime where BDF takes long steps and the Newton systems are hard), 0.05 s: BDF with SPGMR
  // and with the exact reduced solve reach the same states to within their tolerance.
  SceneSpec spec = stiffCube(1e5);
  spec.dElastic = 50.0;
  const World w = buildWorld(spec);
  const Model model(w);
  const State start = initialState(w);
  State direct = start, krylov = start;
  CvodeOptions options;
  options.rtol = 1e-6;
  CvodeIntegrator exact(options);
  options.krylov = true;
  CvodeIntegrator spgmr(options);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(exact.step(model, direct, 0.01).ok);
    ASSERT_TRUE(spgmr.step(model, krylov, 0.01).ok);
  }
  const double moved = (direct.x - start.x).cwiseAbs().maxCoeff();
  EXPECT_GT(moved, 1e-3);
  EXPECT_LT((direct.x - krylov.x).cwiseAbs().maxCoeff(), 1e-3 * moved);
  EXPECT_LT(statsOf(spgmr).at("factorizations"), statsOf(exact).at("factorizations"));
}

TEST(Cvode, TranslatingTheSceneTranslatesTheAnswer) {
  // jello.w's moving cube centred in the box, and the same cube 0.3 m away, both touching
  // nothing for the 0.01 s run: CVODE integrates positions relative to the cube's centre, so
  // its steps and answers are the same.
  World a = test::loadWorld("jello.w");
  a.plane.reset();
  Vec3 centre{};
  for (const Vec3& p : a.positions) centre = centre + p * (1.0 / double(a.positions.size()));
  for (Vec3& p : a.positions) p = p - centre;
  World b = a;
  const Vec3 offset{0.3, -0.3, 0.3};
  for (Vec3& p : b.positions) p = p + offset;
  const Model ma(a), mb(b);
  CvodeOptions options;
  options.rtol = 1e-4;
  CvodeIntegrator ca(options), cb(options);
  State sa = initialState(a), sb = initialState(b);
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(ca.step(ma, sa, 2e-3).ok);
    ASSERT_TRUE(cb.step(mb, sb, 2e-3).ok);
  }
  const int n = sa.numPoints();
  double worst = 0.0;
  for (int p = 0; p < n; ++p)
    worst = std::max(worst, norm(sb.position(p) - offset - sa.position(p)));
  EXPECT_LT(worst, 1e-10);
  EXPECT_EQ(statsOf(ca).at("cvode_steps"), statsOf(cb).at("cvode_steps"));
}

// The first output step (5 ms) that reports a root is the one in which some point first passes
// a surface.
void expectRootsAtTheContactOnset(const World& w) {
  const Model model(w);
  CvodeOptions options;
  options.rtol = 1e-4;
  options.contactRoots = true;
  CvodeIntegrator cvode(options);
  State s = initialState(w);
  int firstRoot = -1, firstContact = -1;
  for (int i = 0; i < 20 && (firstRoot < 0 || firstContact < 0); ++i) {
    const State before = s;
    ASSERT_TRUE(cvode.step(model, s, 5e-3).ok);
    if (firstRoot < 0 && statsOf(cvode).at("contact_roots") > 0) firstRoot = i;
    if (firstContact < 0 && model.contactBegins(before.x.data(), s.x.data())) firstContact = i;
  }
  ASSERT_GE(firstContact, 0) << "the cube reaches a surface within 0.1 s";
  EXPECT_EQ(firstRoot, firstContact);
}

TEST(Cvode, ContactRootsFireAtJellosContactOnset) {
  // jello.w first touches a wall or the plane a few hundredths of a second in.
  expectRootsAtTheContactOnset(test::loadWorld("jello.w"));
}

TEST(Cvode, ContactRootsFireWhereTheCubeMeetsTheCone) {
  // A cube thrown down at 5 m/s onto a cone's apex 0.2 m below its bottom face: the cone's
  // signed distance is its root function.
  SceneSpec spec;
  spec.pose = PosePreset::Rest;
  spec.velocity = {0.0, 0.0, -5.0};
  spec.plane.reset();
  spec.fieldResolution = 0;
  spec.cone = Cone{{0.5, 0.5, -0.2}, {0.0, 0.0, -1.0}, 1.5, 1.0};
  expectRootsAtTheContactOnset(buildWorld(spec));
}

TEST(Cvode, ContactRootsFireWhereTheCubeMeetsTheSpiral) {
  // The showcase's spiral ramp, the cube thrown down onto its first turn; its root function is
  // < 0 exactly inside (checked at random points first).
  const Spiral spiral{0.0, 0.0, 0.6, 0.75, 1.95, 1.3, 1.5, 0.25};
  ModelSpec alone;
  alone.numPoints = 1;
  alone.mass = 1.0;
  alone.walls = false;
  alone.spiral = spiral;
  const Model probe(alone);
  const Obstacle& o = *probe.obstacles().front();
  ASSERT_EQ(o.rootsPerPoint(), 1);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  int inside = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    double g = 0.0;
    const double xs[3] = {x.x, x.y, x.z};
    o.roots(xs, 1, &g);
    const bool in = o.depth(x) > 0.0;
    inside += in;
    EXPECT_EQ(g < 0.0, in) << x.x << " " << x.y << " " << x.z << " g " << g;
  }
  EXPECT_GT(inside, 100);
  SceneSpec spec;
  spec.pose = PosePreset::Translated;
  spec.translate = {0.55, 0.55, 0.55};
  spec.velocity = {0.0, 0.0, -5.0};
  spec.plane.reset();
  spec.fieldResolution = 0;
  spec.spiral = spiral;
  expectRootsAtTheContactOnset(buildWorld(spec));
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
