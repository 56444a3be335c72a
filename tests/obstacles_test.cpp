// The cone and the spiral ramp: forces against finite differences of their energy, Jacobians
// against finite differences of the forces, the world file's extensions, and a cube that comes to
// rest on each instead of falling through.
#include "src/effects/obstacles.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <fstream>
#include <functional>
#include <random>

#include "solvers/simulation.h"
#include "solvers/system/jacobian.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

const Cone kCone{{0.2, -0.1, 0.0}, {0.1, 0.2, -1.0}, 1.8, 1.1};  // tilted, apex up
const Spiral kSpiral{0.1, -0.2, 1.0, 0.4, 1.6, 1.2, 1.5, 0.3};

ModelSpec onePoint(const std::optional<Cone>& cone, const std::optional<Spiral>& spiral) {
  ModelSpec spec;
  spec.numPoints = 1;
  spec.mass = 0.01;
  spec.walls = false;
  spec.contact = {1000.0, 0.3};
  spec.cone = cone;
  spec.spiral = spiral;
  return spec;
}

State at(const Vec3& x, const Vec3& v = {0, 0, 0}) {
  return test::pointAt(x, v);
}

// Random points of the box [-2, 2]^3 inside the obstacle, away from where the nearest face
// changes (there the force is continuous but the Jacobian jumps).
std::vector<Vec3> insidePoints(const std::function<std::optional<Penetration>(const Vec3&)>& pen,
                               int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<Vec3> points;
  while (int(points.size()) < count) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    const auto p = pen(x);
    if (!p || p->depth < 1e-3) continue;
    bool smooth = true;
    for (const Vec3& d : {Vec3{1e-4, 0, 0}, Vec3{0, 1e-4, 0}, Vec3{0, 0, 1e-4}}) {
      for (double s : {-1.0, 1.0}) {
        const auto q = pen(x + d * s);
        // The same face on both sides: the gradient barely changes.
        smooth = smooth && q && norm(q->gradient - p->gradient) < 1e-2;
      }
    }
    if (smooth) points.push_back(x);
  }
  return points;
}

double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1e-12, b.cwiseAbs().maxCoeff());
}

void checkAgainstFiniteDifferences(const Model& model, const Vec3& x) {
  const double h = 1e-6;
  // The force is minus the energy's gradient (undamped: at rest).
  const State s = at(x);
  Eigen::VectorXd f;
  model.forces(s.x, s.v, f);
  Eigen::Vector3d grad;
  for (int i = 0; i < 3; ++i) {
    State p = s, m = s;
    p.x[i] += h;
    m.x[i] -= h;
    grad[i] = (model.potentialEnergy(p.x.data()) - model.potentialEnergy(m.x.data())) / (2 * h);
  }
  EXPECT_LT((f + grad).norm(), 1e-5 * std::max(1.0, f.norm()))
      << "at " << x.x << " " << x.y << " " << x.z;
  // K against differences of the force (the curvature term included), D against the velocity's.
  const State moving = at(x, {0.4, -0.7, 0.3});
  JacobianAssembler jac(model);
  jac.assemble(moving.x.data(), {.clampCompression = false});
  Eigen::MatrixXd K(3, 3), D(3, 3);
  Eigen::VectorXd fp, fm;
  for (int j = 0; j < 3; ++j) {
    State p = s, m = s;  // at rest: the damping's x-derivative (omitted, as for the sphere) is 0
    p.x[j] += h;
    m.x[j] -= h;
    model.forces(p.x, p.v, fp);
    model.forces(m.x, m.v, fm);
    K.col(j) = (fp - fm) / (2 * h);
    State pv = moving, mv = moving;
    pv.v[j] += h;
    mv.v[j] -= h;
    model.forces(pv.x, pv.v, fp);
    model.forces(mv.x, mv.v, fm);
    D.col(j) = (fp - fm) / (2 * h);
  }
  EXPECT_LT(relativeError(Eigen::MatrixXd(jac.K()), K), 1e-5)
      << "at " << x.x << " " << x.y << " " << x.z;
  EXPECT_LT(relativeError(Eigen::MatrixXd(jac.D()), D), 1e-6);
  // Clamped, -K is semidefinite.
  jac.assemble(moving.x.data(), {});
  EXPECT_GT(test::symmetricEigenvalues(-Eigen::MatrixXd(jac.K())).minCoeff(), -1e-9);
}

TEST(Cone, ForcesAndJacobiansMatchFiniteDifferences) {
  const Model model(onePoint(kCone, std::nullopt));
  const auto points = insidePoints([](const Vec3& x) { return conePenetration(kCone, x); }, 40);
  for (const Vec3& x : points) checkAgainstFiniteDifferences(model, x);
}

TEST(Cone, DepthIsTheDistanceToTheNearerSurfaceAndOutsideIsFree) {
  const Cone upright{{0, 0, 0}, {0, 0, -1}, 2.0, 1.0};  // apex at the origin, base at z = -2
  // On the axis 0.5 below the apex: the lateral surface is 0.5 sin(atan(1/2)) away.
  const auto p = conePenetration(upright, {0, 0, -0.5});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->depth, 0.5 / std::sqrt(5.0), 1e-12);
  // Just above the base disk's centre: the base is nearer.
  const auto q = conePenetration(upright, {0, 0, -1.95});
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(q->depth, 0.05, 1e-12);
  EXPECT_EQ(q->gradient, (Vec3{0, 0, 1}));
  EXPECT_FALSE(conePenetration(upright, {0.6, 0, -1.0}).has_value());  // outside the slope
  EXPECT_FALSE(conePenetration(upright, {0, 0, 0.1}).has_value());     // above the apex
  EXPECT_FALSE(conePenetration(upright, {0, 0, -2.1}).has_value());    // below the base
}

TEST(Spiral, ForcesAndJacobiansMatchFiniteDifferences) {
  const Model model(onePoint(std::nullopt, kSpiral));
  const auto points = insidePoints([](const Vec3& x) { return spiralPenetration(kSpiral, x); }, 40);
  for (const Vec3& x : points) checkAgainstFiniteDifferences(model, x);
}

TEST(Spiral, TheRampDescendsOnePitchPerTurnAndHasOneSlabPerTurn) {
  const Spiral s{0, 0, 1.0, 0.5, 1.5, 1.0, 1.5, 0.2};  // turns 1.5: the ramp spans 3 pi
  // A quarter turn from the start (the +y direction) the top is 0.25 below zTop.
  const auto quarter = spiralPenetration(s, {0.0, 1.0, 0.70});
  ASSERT_TRUE(quarter.has_value());
  EXPECT_NEAR(quarter->depth, 0.05, 1e-12);
  EXPECT_NEAR(quarter->gradient.z, -1.0, 1e-12);  // pushed up
  // One turn lower at the same angle: the second slab; a third would start past 3 pi.
  const auto second = spiralPenetration(s, {0.0, 1.0, -0.30});
  ASSERT_TRUE(second.has_value());
  EXPECT_NEAR(second->depth, 0.05, 1e-12);
  EXPECT_FALSE(spiralPenetration(s, {0.0, 1.0, -1.30}).has_value());
  // Between the slabs, inside the hole and beyond the outer radius: free.
  EXPECT_FALSE(spiralPenetration(s, {0.0, 1.0, 0.30}).has_value());
  EXPECT_FALSE(spiralPenetration(s, {0.0, 0.2, 0.70}).has_value());
  EXPECT_FALSE(spiralPenetration(s, {0.0, 1.7, 0.70}).has_value());
  // Near the start, the end face is nearer than the top: depth r Theta.
  const double theta = 0.02;
  const auto start = spiralPenetration(s, {std::cos(theta), std::sin(theta), 0.9});
  ASSERT_TRUE(start.has_value());
  EXPECT_NEAR(start->depth, theta, 1e-12);
}

TEST(ObstacleWorlds, ConeAndSpiralRoundTripThroughTheWorldFileAndBadOnesAreRefused) {
  test::TempDir dir;
  World w = test::loadWorld("jello.w");
  w.cone = kCone;
  w.spiral = kSpiral;
  EXPECT_TRUE(w.usesExtensions());
  const auto path = dir.path() / "obstacles.w";
  writeWorld(w, path);
  const World back = readWorld(path);
  EXPECT_EQ(back.cone, w.cone);
  EXPECT_EQ(back.spiral, w.spiral);

  const std::string text = test::readFile(path);
  const auto refused = [&](const std::string& from, const std::string& to, const std::string& why) {
    std::string bad = text;
    const std::size_t at = bad.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    bad.replace(at, from.size(), to);
    const auto badPath = dir.path() / "bad.w";
    std::ofstream(badPath) << bad;
    try {
      (void)readWorld(badPath);
      ADD_FAILURE() << "accepted: " << to;
    } catch (const WorldFileError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  refused("cone 0.2000", "cone 0.2 -0.1 0 0 0 0 1 1 cone 0.2000", "axis must not be zero");
  refused("spiral 0.1000", "spiral 0 0 1 0.5 0.4 1 1 0.1 spiral 0.1000", "outer radius");
  refused("spiral 0.1000", "spiral 0 0 1 0.5 1.5 0.2 1 0.3 spiral 0.1000", "less than its pitch");
}

// A cube dropped onto an obstacle is held by it: over 2.5 s no point is ever more than 12 cm inside
// (it does not fall through), the contact never adds energy (kinetic + spring + contact minus
// the field's work only falls, by damping), and it ends above the box's floor. Frictionless, it
// slides off a slope: resting on it is not asked.
void expectHolds(World w, const std::function<std::optional<Penetration>(const Vec3&)>& pen,
                 double floorClearance) {
  w.integrator = IntegratorKind::RK4;
  Simulation sim(w);
  const auto balance = [&] { return sim.model().energy(sim.state()).total() - sim.fieldWork(); };
  double deepest = 0.0, previous = balance();
  while (sim.state().t < 2.5) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << sim.state().t << " " << r.message;
    if (sim.steps() % 50 != 0) continue;
    for (int p = 0; p < sim.state().numPoints(); ++p) {
      if (const auto q = pen(sim.state().position(p))) deepest = std::max(deepest, q->depth);
    }
    const double now = balance();
    EXPECT_LT(now, previous + 1e-6 * (1.0 + std::abs(previous))) << "t = " << sim.state().t;
    previous = now;
  }
  // A 1 m fall onto a few points of a soft penalty (kc = 400 N/m) dents some 8 cm; falling
  // through would pass half the spiral's 25 cm slab.
  EXPECT_LT(deepest, 0.12);
  double zmin = 1e9;
  for (int p = 0; p < sim.state().numPoints(); ++p) {
    zmin = std::min(zmin, sim.state().position(p).z);
  }
  EXPECT_GT(zmin, -2.0 + floorClearance);
}

World dropScene(const Vec3& offset) {
  World w = test::loadWorld("sphere-drop.w");
  w.sphere.reset();
  w.plane.reset();
  w.dt = 0.001;
  for (Vec3& v : w.velocities) v = {};
  Vec3 centre;
  for (const Vec3& x : w.positions) centre = centre + x * (1.0 / double(w.positions.size()));
  for (Vec3& x : w.positions) x = x - centre + offset;
  return w;
}

TEST(ObstacleWorlds, TheConeAndTheSpiralHoldADroppedCube) {
  World cone = dropScene({0.0, 0.0, 1.2});
  cone.cone = Cone{{0, 0, 0.2}, {0, 0, -1}, 2.2, 1.6};
  expectHolds(
      cone, [&](const Vec3& x) { return conePenetration(*cone.cone, x); }, -0.05);
  // The spiral's lowest turn ends 0.2 m above the floor: the cube slides down it.
  World spiral = dropScene({1.1, 0.0, 1.3});
  spiral.spiral = Spiral{0, 0, 0.6, 0.3, 1.9, 1.2, 1.2, 0.25};
  expectHolds(
      spiral, [&](const Vec3& x) { return spiralPenetration(*spiral.spiral, x); }, -0.05);
}

}  // namespace
}  // namespace jello
