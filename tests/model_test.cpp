// The model builds only the effects a scene has, and absent effects are never evaluated.
#include "src/model.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "src/base/parallel.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

TEST(Model, BuildsOnlyTheEffectsTheSceneHas) {
  const Model moveLeft(test::loadWorld("moveLeft.w"));  // no plane, all-zero field
  EXPECT_TRUE(moveLeft.has(ObstacleKind::Walls));
  EXPECT_FALSE(moveLeft.has(ObstacleKind::Plane));
  EXPECT_FALSE(moveLeft.hasField());
  EXPECT_FALSE(moveLeft.has(ObstacleKind::Sphere));

  const Model rotate(test::loadWorld("rotate.w"));
  EXPECT_TRUE(rotate.has(ObstacleKind::Plane));
  EXPECT_TRUE(rotate.hasField());
}

TEST(Model, AnAbsentEffectIsNotEvaluated) {
  const World w = test::loadWorld("moveLeft.w");
  const Model model(w);
  const State s = initialState(w);
  Eigen::VectorXd f;
  for (int i = 0; i < 5; ++i) model.forces(s.x, s.v, f);
  EXPECT_EQ(model.counts().springs, 5);
  EXPECT_EQ(model.counts().of(ObstacleKind::Plane), 0);
  EXPECT_EQ(model.counts().of(ObstacleKind::Sphere), 0);
  EXPECT_EQ(model.counts().field, 0);
  EXPECT_EQ(model.counts().of(ObstacleKind::Walls), 0);  // the cube starts inside the box
  EXPECT_EQ(model.counts().skippedOf(ObstacleKind::Walls), 5);
}

TEST(Model, AUserForceIsAddedAsGivenAndCostsNothingOnceCleared) {
  const World w = test::loadWorld("moveLeft.w");
  Model model(w);
  const State s = initialState(w);
  Eigen::VectorXd base, pushed;
  model.forces(s.x, s.v, base);
  const Eigen::VectorXd user = Eigen::VectorXd::LinSpaced(s.x.size(), -1.0, 1.0);
  model.setUserForce(user);
  model.forces(s.x, s.v, pushed);
  EXPECT_TRUE(pushed.isApprox(base + user, 1e-14));
  EXPECT_EQ(model.counts().user, 1);
  model.clearUserForce();
  model.forces(s.x, s.v, pushed);
  EXPECT_EQ(pushed, base);
  EXPECT_EQ(model.counts().user, 1);
}

TEST(Model, WallsAreEvaluatedOnceAPointIsOutside) {
  World w = test::loadWorld("moveLeft.w");
  w.positions[0].x = -2.01;
  const Model model(w);
  const State s = initialState(w);
  Eigen::VectorXd f, g;
  model.forces(s.x, s.v, f);
  EXPECT_EQ(model.counts().of(ObstacleKind::Walls), 1);
  EXPECT_GT(f[0], 0.0);  // pushed back in +x

  World inside = w;
  inside.positions[0].x = 0.0;
  const Model free(inside);
  const State t = initialState(inside);
  free.forces(t.x, t.v, g);
  EXPECT_EQ(free.counts().skippedOf(ObstacleKind::Walls), 1);
}

TEST(Model, AUniformFieldAddsTheSameForceToEveryPoint) {
  const World w = test::loadWorld("gravity.w");
  const Model model(w);
  ModelSpec noField = modelSpecFromWorld(w);
  noField.field = {};
  const Model without(noField);
  const State s = initialState(w);
  Eigen::VectorXd f, g;
  model.forces(s.x, s.v, f);
  without.forces(s.x, s.v, g);
  const int n = model.numPoints();
  for (int p = 0; p < n; ++p) {
    EXPECT_NEAR(f[2 * n + p] - g[2 * n + p], -0.06, 1e-15);
    EXPECT_EQ(f[p], g[p]);
  }
}

TEST(Model, EnergyAddsKineticSpringAndContact) {
  World w = test::loadWorld("jello.w");
  w.positions[5].z = 2.1;  // into the top wall by 0.1 m
  const Model model(w);
  const State s = initialState(w);
  const Energy e = model.energy(s);
  EXPECT_NEAR(e.kinetic, 0.5 * 512 * 0.001953 * (100 + 100 + 400), 1e-9);
  EXPECT_NEAR(e.contact, 0.5 * 400 * 0.1 * 0.1, 1e-12);
  EXPECT_GT(e.spring, 0.0);
  EXPECT_DOUBLE_EQ(e.total(), e.kinetic + e.spring + e.contact);
}

// The acceleration fused with a step's update (RK4 uses it) is split over threads by point
// ranges from 32^3 up: with every effect at work (walls on one side only, plane, sphere, field,
// user force) it equals the serial acceleration to round-off, hands each point to then() once,
// and counts each effect once.
TEST(Model, ThreadedAccelerationThenEqualsTheSerialOne) {
  World w = resampleCube(test::loadWorld("rotate.w"), 32);  // a field
  State s = initialState(w);
  const int n = w.cubeResolution * w.cubeResolution * w.cubeResolution;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) {
    s.x[i] += jitter(rng);
    s.v[i] = 10.0 * jitter(rng);
  }
  // Into the +x wall: only the last points (the largest i) are outside.
  s.x.head(n).array() += kBoxHalfSize + 0.05 - s.x.head(n).maxCoeff();
  const Vec3 c = s.centroid();
  w.plane = Plane{0.3, 0.2, 1.0, -(0.3 * c.x + 0.2 * c.y + c.z)};  // through the centre
  w.sphere = Sphere{c, 0.3};
  Model model(w);
  model.setUserForce(Eigen::VectorXd::LinSpaced(3 * n, -1.0, 1.0));
  ASSERT_GT(model.obstacle(ObstacleKind::Walls)->energy(s.x.data(), n), 0.0);
  ASSERT_GT(model.obstacle(ObstacleKind::Plane)->energy(s.x.data(), n), 0.0);
  ASSERT_GT(model.obstacle(ObstacleKind::Sphere)->energy(s.x.data(), n), 0.0);
  ASSERT_GT(s.x.head(n).minCoeff(), -kBoxHalfSize);
  setParallelThreads(1);
  Eigen::VectorXd serial(3 * n);
  model.acceleration(s.x.data(), s.v.data(), serial.data());
  for (int threads : {1, 2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    setParallelThreads(threads);
    const EffectCounts before = model.counts();
    std::vector<int> visits(static_cast<std::size_t>(n), 0);
    Eigen::VectorXd a = Eigen::VectorXd::Constant(3 * n, 1e300);  // a missed zeroing shows
    model.acceleration(s.x.data(), s.v.data(), a.data(), [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
      for (std::ptrdiff_t p = lo; p < hi; ++p) ++visits[static_cast<std::size_t>(p)];
    });
    EXPECT_LE((a - serial).cwiseAbs().maxCoeff(), 1e-12 * serial.cwiseAbs().maxCoeff());
    if (threads == 1) {
      EXPECT_EQ(a, serial);
    }
    EXPECT_EQ(std::count(visits.begin(), visits.end(), 1), n);
    const EffectCounts after = model.counts();
    EXPECT_EQ(after.springs - before.springs, 1);
    for (ObstacleKind kind : {ObstacleKind::Walls, ObstacleKind::Plane, ObstacleKind::Sphere}) {
      EXPECT_EQ(after.of(kind) - before.of(kind), 1) << obstacleName(kind);
      EXPECT_EQ(after.skippedOf(kind), before.skippedOf(kind)) << obstacleName(kind);
    }
    EXPECT_EQ(after.field - before.field, 1);
    EXPECT_EQ(after.user - before.user, 1);
  }
  setParallelThreads(1);
}

// The viewer's setting (its drawing thread is busy all the time): loops split over one CPU fewer
// than the process may run on, at least one; JELLO_THREADS, when set, decides instead.
TEST(Parallel, LeavingOneCpuFreeSplitsOverOneFewerUnlessJelloThreadsIsSet) {
  cpu_set_t set;
  ASSERT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  const int cpus = std::min(CPU_COUNT(&set), 8);
  const char* env = std::getenv("JELLO_THREADS");
  const std::string saved = env ? env : "";
  ::unsetenv("JELLO_THREADS");
  setParallelThreads(7);
  leaveOneCpuFree();
  EXPECT_EQ(parallelThreads(), std::max(1, cpus - 1));
  ::setenv("JELLO_THREADS", "3", 1);
  setParallelThreads(5);
  leaveOneCpuFree();
  EXPECT_EQ(parallelThreads(), 5);  // left as it was
  if (env) {
    ::setenv("JELLO_THREADS", saved.c_str(), 1);
  } else {
    ::unsetenv("JELLO_THREADS");
  }
  setParallelThreads(1);
}

// Model::forces is const and keeps no scratch: two threads evaluating one model at different
// states get, bit for bit, what one thread gets (a shared scratch buffer would mix the states).
TEST(Model, TwoThreadsEvaluatingOneModelGetWhatOneThreadGets) {
  const World w = test::loadWorld("jello.w");
  const Model model(w);
  std::mt19937 rng(7);
  std::normal_distribution<double> jitter(0.0, 0.02);
  std::vector<State> states(4, initialState(w));
  std::vector<Eigen::VectorXd> expected(states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    for (Eigen::Index j = 0; j < states[i].x.size(); ++j) {
      states[i].x[j] += jitter(rng);
      states[i].v[j] += jitter(rng);
    }
    model.forces(states[i].x, states[i].v, expected[i]);
  }
  const long before = model.counts().springs;
  constexpr int kRounds = 300;
  std::atomic<int> mismatches{0};
  const auto work = [&](std::size_t offset) {
    Eigen::VectorXd f;
    for (int r = 0; r < kRounds; ++r) {
      const std::size_t i = (offset + static_cast<std::size_t>(r)) % states.size();
      model.forces(states[i].x, states[i].v, f);
      if (f != expected[i]) ++mismatches;
    }
  };
  std::thread other(work, 1);
  work(0);
  other.join();
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(model.counts().springs - before, 2 * kRounds);  // counters are atomic
}

}  // namespace
}  // namespace jello
