// Hard, stiff cases stay numerically stable under the implicit integrators (each case its own
// test): run 2 simulated seconds with no non-finite value, no point more than 0.5 m beyond a
// wall, and total energy (kinetic + spring + contact) never above 1.05 times its start plus the
// work done by the field. The explicit integrators at the same step are reported as diverged.
#include <gtest/gtest.h>

#include <cmath>

#include "solvers/simulation.h"
#include "src/scene_builder.h"

namespace jello {
namespace {

struct HardCase {
  std::string name;
  World world;
  double dt;  // s
  friend void PrintTo(const HardCase& c, std::ostream* os) { *os << c.name; }
};

World stiff(double k) {
  return buildWorld(stiffCube(k));
}

World thrownIntoAWall() {
  SceneSpec spec;
  spec.kCollision = 1e5;
  spec.plane.reset();
  spec.fieldResolution = 0;
  spec.pose = PosePreset::Rest;
  spec.velocity = {-20.0, 0.0, 0.0};
  return buildWorld(spec);
}

World crushedAgainstThePlane() {
  // jello.w's plane -x + y + z + 2 = 0, and a uniform push of 2 N per point (100 g) into it.
  SceneSpec spec;
  spec.pose = PosePreset::Rest;
  spec.velocity = {5.0, -5.0, -5.0};
  spec.fieldResolution = 2;
  World w = buildWorld(spec);
  const Vec3 push = Vec3{1.0, -1.0, -1.0} * (2.0 / std::sqrt(3.0));
  for (Vec3& f : w.field.forces) f = push;
  return w;
}

World compressedToHalf() {
  World w = stiff(1e4);
  const Vec3 c{0.5, 0.5, 0.5};
  const Lattice lat{w.cubeResolution};
  for (int i = 0; i < lat.n; ++i)
    for (int j = 0; j < lat.n; ++j)
      for (int k = 0; k < lat.n; ++k)  // every spring at half its rest length
        w.positions[lat.index(i, j, k)] = c + (lat.restPosition(i, j, k) - c) * 0.5;
  return w;
}

std::vector<HardCase> hardCases() {
  return {{"StiffK1e4Dt001", stiff(1e4), 0.01},
          {"StiffK1e4Dt005", stiff(1e4), 0.05},
          {"StiffK1e5Dt001", stiff(1e5), 0.01},
          {"StiffK1e5Dt005", stiff(1e5), 0.05},
          {"ThrownIntoAWallWithKCollision1e5", thrownIntoAWall(), 0.01},
          {"CrushedAgainstThePlane", crushedAgainstThePlane(), 0.01},
          {"EverySpringAtHalfItsRestLength", compressedToHalf(), 0.01}};
}

// Work done by a uniform field since the start: sum over points of F . (x - x0).
double fieldWork(const World& w, const State& start, const State& now) {
  if (w.field.empty()) return 0.0;
  const Vec3 F = w.field.forces.front();
  double work = 0.0;
  for (int p = 0; p < now.numPoints(); ++p) work += dot(F, now.position(p) - start.position(p));
  return work;
}

void expectStableForTwoSeconds(const HardCase& c, IntegratorKind kind, SolverOptions options) {
  Simulation sim(c.world, kind, c.dt, options);
  const State start = sim.state();
  const double e0 = sim.model().energy(start).total();
  const long steps = std::lround(2.0 / c.dt);
  double worstRatio = 0.0, deepest = 0.0;
  for (long i = 0; i < steps; ++i) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    const State& s = sim.state();
    ASSERT_TRUE(s.x.allFinite() && s.v.allFinite());
    deepest = std::max(deepest, s.x.cwiseAbs().maxCoeff() - 2.0);
    const double budget = e0 + fieldWork(c.world, start, s);
    worstRatio = std::max(worstRatio, sim.model().energy(s).total() / budget);
  }
  EXPECT_NEAR(sim.state().t, 2.0, 1e-9);
  EXPECT_LE(deepest, 0.5) << "m beyond a wall";
  EXPECT_LE(worstRatio, 1.05) << "energy over its budget";
}

class HardCaseTest : public ::testing::TestWithParam<HardCase> {};

TEST_P(HardCaseTest, ImplicitStaysStable) {
  expectStableForTwoSeconds(GetParam(), IntegratorKind::Implicit, {});
}

TEST_P(HardCaseTest, CvodeStaysStable) {
  SolverOptions options;
  options.cvode.rtol = 1e-3;
  options.cvode.linearSolver = LinearSolverKind::Cg;  // 3-4x faster than CHOLMOD at 8^3
  expectStableForTwoSeconds(GetParam(), IntegratorKind::Cvode, options);
}

INSTANTIATE_TEST_SUITE_P(Named, HardCaseTest, ::testing::ValuesIn(hardCases()),
                         [](const auto& param_info) { return param_info.param.name; });

class StiffCaseExplicit
    : public ::testing::TestWithParam<std::tuple<double, double, IntegratorKind>> {};

TEST_P(StiffCaseExplicit, IsReportedAsDivergedNotCrashed) {
  const auto [k, dt, kind] = GetParam();
  Simulation sim(stiff(k), kind, dt);
  bool diverged = false;
  for (int i = 0; i < 400 && !diverged; ++i) diverged = !sim.step().ok;
  ASSERT_TRUE(diverged);
  EXPECT_EQ(sim.divergence()->integrator, kind);
  EXPECT_TRUE(sim.state().x.allFinite());  // the last sane state is kept
}

std::string explicitCaseName(
    const ::testing::TestParamInfo<StiffCaseExplicit::ParamType>& param_info) {
  const auto [k, dt, kind] = param_info.param;
  return std::string(integratorName(kind)) + (k > 5e4 ? "K1e5" : "K1e4") +
         (dt > 0.02 ? "Dt005" : "Dt001");
}

INSTANTIATE_TEST_SUITE_P(
    K1e4AndK1e5, StiffCaseExplicit,
    ::testing::Combine(::testing::Values(1e4, 1e5), ::testing::Values(0.01, 0.05),
                       ::testing::Values(IntegratorKind::Euler, IntegratorKind::RK4)),
    explicitCaseName);

}  // namespace
}  // namespace jello
