// The contact laws (src/world/contact_law.h, src/effects/obstacle.h): the smooth law is C2 in
// the depth and its derivatives are each other's; on every solid, alone and two at a corner,
// its forces are minus its energy's gradient and its Jacobians the forces' derivatives; every
// solid's penetrations give back its penalty; the world file's `contact` extension round-trips
// and bad ones are refused naming the token; a file without it is the penalty. The barrier:
// the same checks outside the solids within dhat, its distances exact (the cone's against a
// brute-force search), its step bounds never let a point in, and worlds that cannot hold it
// (a spiral, a point inside) are refused.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <random>

#include "solvers/simulation.h"
#include "solvers/system/jacobian.h"
#include "src/model.h"
#include "src/world/world_reader.h"
#include "src/world/world_writer.h"
#include "tests/test_support.h"

namespace jello {
namespace {

constexpr double kLayer = 0.05;
const ContactConstants kSmooth{1000.0, 0.3, ContactModel::Smooth, kLayer};
const ContactConstants kPenalty{1000.0, 0.3};

using test::onePoint;

// One model per solid, each alone (the walls too).
std::vector<ModelSpec> everySolid(const ContactConstants& k) {
  std::vector<ModelSpec> specs(5, onePoint(k));
  specs[0].walls = true;
  specs[1].plane = Plane{-1, 1, 2, 2};
  specs[2].sphere = Sphere{{0.1, -0.2, 0.3}, 0.9};
  specs[3].cone = Cone{{0.2, -0.1, 0.0}, {0.1, 0.2, -1.0}, 1.8, 1.1};
  specs[4].spiral = Spiral{0.1, -0.2, 1.0, 0.4, 1.6, 1.2, 1.5, 0.3};
  return specs;
}

State at(const Vec3& x, const Vec3& v = {0, 0, 0}) {
  return test::pointAt(x, v);
}

// Random points of [-2.1, 2.1]^3 touching the model's one solid at depth in [1e-3, deepest],
// away from where its nearest face changes (there the force is continuous but its Jacobian
// jumps).
std::vector<Vec3> touchingPoints(const Obstacle& o, double deepest, int count) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2.1, 2.1);
  std::vector<Vec3> points;
  Penetration a[kMaxPenetrations], b[kMaxPenetrations];
  for (long tries = 0; int(points.size()) < count && tries < 10000000; ++tries) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    if (o.penetrations(x, a) != 1 || a[0].depth < 1e-3 || a[0].depth > deepest) continue;
    bool same = true;
    for (const Vec3& d : {Vec3{1e-4, 0, 0}, Vec3{0, 1e-4, 0}, Vec3{0, 0, 1e-4}}) {
      for (double s : {-1.0, 1.0}) {
        same =
            same && o.penetrations(x + d * s, b) == 1 && norm(b[0].gradient - a[0].gradient) < 1e-2;
      }
    }
    if (same) points.push_back(x);
  }
  EXPECT_EQ(int(points.size()), count);
  return points;
}

double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1e-12, b.cwiseAbs().maxCoeff());
}

// f = -grad(E) at rest; D against differences of the force in v while moving; K against its
// differences in x, while moving on flat solids (K then holds the damping's dependence on x
// through the smooth law's weight), at rest on curved ones (where the damping's normal also
// turns with x: a term c w |v| / R, not symmetric, that K leaves out).
bool flat(const Obstacle& o) {
  return o.kind() == ObstacleKind::Walls || o.kind() == ObstacleKind::Plane;
}

void expectConsistent(const Model& model, const Vec3& x) {
  const bool allFlat =
      std::ranges::all_of(model.obstacles(), [](const auto& o) { return flat(*o); });
  const double h = 1e-6;
  const State s = at(x);
  Eigen::VectorXd f, fp, fm;
  model.forces(s.x, s.v, f);
  Eigen::Vector3d grad;
  Eigen::MatrixXd K(3, 3), D(3, 3);
  const State moving = at(x, {0.4, -0.7, 0.3});
  const Eigen::VectorXd kv = allFlat ? moving.v : s.v;  // the velocity K is checked at
  for (int j = 0; j < 3; ++j) {
    State p = s, m = s;
    p.x[j] += h;
    m.x[j] -= h;
    grad[j] = (model.potentialEnergy(p.x.data()) - model.potentialEnergy(m.x.data())) / (2 * h);
    p.v = m.v = kv;
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
  const std::string where =
      std::to_string(x.x) + " " + std::to_string(x.y) + " " + std::to_string(x.z);
  EXPECT_LT((f + grad).norm(), 1e-6 * std::max(1.0, f.norm())) << where;
  JacobianAssembler jac(model);
  jac.assemble(moving.x.data(), {.clampCompression = false, .velocities = kv.data()});
  EXPECT_LT(relativeError(Eigen::MatrixXd(jac.K()), K), 1e-5) << where;
  EXPECT_LT(relativeError(Eigen::MatrixXd(jac.D()), D), 1e-6) << where;
  // Clamped, -K is semidefinite, moving in or out.
  jac.assemble(moving.x.data(), {.velocities = moving.v.data()});
  EXPECT_GT(test::symmetricEigenvalues(-Eigen::MatrixXd(jac.K())).minCoeff(), -1e-9) << where;
  const Eigen::VectorXd out = -moving.v;
  jac.assemble(moving.x.data(), {.velocities = out.data()});
  EXPECT_GT(test::symmetricEigenvalues(-Eigen::MatrixXd(jac.K())).minCoeff(), -1e-9) << where;
}

TEST(SmoothContactLaw, IsC2InTheDepthAndZeroWithItsDerivativesAtTheSurface) {
  const double k = 1000.0, layer = 0.01;
  const ContactLawValue surface = smoothContactLaw(0.0, k, layer);
  EXPECT_EQ(surface.energy, 0.0);
  EXPECT_EQ(surface.force, 0.0);
  EXPECT_EQ(surface.stiffness, 0.0);
  EXPECT_EQ(smoothContactLaw(-0.1, k, layer).energy, 0.0);  // outside: nothing
  // Value, slope and curvature agree on both sides of the layer's end.
  const ContactLawValue below = smoothContactLaw(layer * (1 - 1e-12), k, layer);
  const ContactLawValue above = smoothContactLaw(layer * (1 + 1e-12), k, layer);
  EXPECT_NEAR(below.energy, above.energy, 1e-10 * above.energy);
  EXPECT_NEAR(below.force, above.force, 1e-9 * above.force);
  EXPECT_NEAR(below.stiffness, above.stiffness, 1e-9 * above.stiffness);
  EXPECT_DOUBLE_EQ(above.stiffness, k);  // past the layer: the penalty's stiffness
  // Deep, the penalty shifted by half the layer: the same force kc layer/2 shallower.
  EXPECT_NEAR(smoothContactLaw(0.3, k, layer).force, k * (0.3 - layer / 2), 1e-9);
  // Each derivative is the one before's, by central differences, inside and past the layer.
  for (double q : {0.001, 0.004, 0.0099, 0.0101, 0.02, 0.5}) {
    const double h = 1e-7;
    const ContactLawValue p = smoothContactLaw(q + h, k, layer),
                          m = smoothContactLaw(q - h, k, layer);
    const ContactLawValue c = smoothContactLaw(q, k, layer);
    EXPECT_NEAR((p.energy - m.energy) / (2 * h), c.force, 1e-6 * std::max(1.0, c.force)) << q;
    EXPECT_NEAR((p.force - m.force) / (2 * h), c.stiffness, 1e-5 * std::max(1.0, c.stiffness)) << q;
  }
}

TEST(SmoothContact, ForcesAndJacobiansMatchFiniteDifferencesOnEverySolid) {
  for (const ModelSpec& spec : everySolid(kSmooth)) {
    const Model model(spec);
    ASSERT_EQ(model.obstacles().size(), 1u);
    const Obstacle& o = *model.obstacles()[0];
    SCOPED_TRACE(std::string(obstacleName(o.kind())));
    // Inside the layer (where the law is cubic) and past it.
    for (const Vec3& x : touchingPoints(o, kLayer, 12)) expectConsistent(model, x);
    for (const Vec3& x : touchingPoints(o, 10.0, 12)) expectConsistent(model, x);
  }
}

TEST(SmoothContact, ForcesAndJacobiansMatchFiniteDifferencesWithinTheLayerOfTwoOrThreeSolids) {
  ModelSpec spec = onePoint(kSmooth);
  spec.walls = true;
  spec.plane = Plane{0, 0, 1, 1.97};  // the floor raised 3 cm
  const Model model(spec);
  for (const Vec3& x : {Vec3{2.01, -2.03, 0.5},       // two walls, inside both layers
                        Vec3{2.03, 2.04, -1.99},      // a wall and the plane
                        Vec3{-2.02, 2.01, -2.04}}) {  // two walls, the plane and the floor
    expectConsistent(model, x);
  }
}

// Every solid's penetrations say what its penalty does: energy 1/2 kc q^2 and force
// -kc q grad(q) summed over them.
TEST(SmoothContact, PenetrationsGiveBackEverySolidsPenalty) {
  for (const ModelSpec& spec : everySolid(kPenalty)) {
    const Model model(spec);
    const Obstacle& o = *model.obstacles()[0];
    SCOPED_TRACE(std::string(obstacleName(o.kind())));
    Penetration touch[kMaxPenetrations];
    for (const Vec3& x : touchingPoints(o, 10.0, 20)) {
      const State s = at(x);
      double energy = 0.0;
      Vec3 force;
      const int count = o.penetrations(x, touch);
      for (int i = 0; i < count; ++i) {
        energy += 0.5 * 1000.0 * touch[i].depth * touch[i].depth;
        force = force + touch[i].gradient * (-1000.0 * touch[i].depth);
        // Exact distances have unit gradients; the spiral's vertical depth sqrt(1 + c^2/r^2).
        if (o.kind() != ObstacleKind::Spiral) {
          EXPECT_NEAR(norm(touch[i].gradient), 1.0, 1e-12);
        }
      }
      EXPECT_NEAR(o.energy(s.x.data(), 1), energy, 1e-12 * energy);
      Eigen::VectorXd f;
      model.forces(s.x, s.v, f);
      EXPECT_LT(norm(Vec3{f[0], f[1], f[2]} - force), 1e-9 * norm(force));
      EXPECT_NEAR(o.depth(x), touch[0].depth, 1e-12);
    }
  }
}

// At the surface the penalty's stiffness jumps to kc while the smooth law's starts from 0.
TEST(SmoothContact, StiffnessRisesFromZeroAtTheSurfaceWhereThePenaltysJumps) {
  for (const ContactConstants& k : {kPenalty, kSmooth}) {
    ModelSpec spec = onePoint(k);
    spec.plane = Plane{0, 0, 1, 0};
    const Model model(spec);
    JacobianAssembler jac(model);
    const State s = at({0.1, 0.2, -1e-9}, {0, 0, -1.0});
    jac.assemble(s.x.data(), {});
    const double kzz = -Eigen::MatrixXd(jac.K())(2, 2), dzz = -Eigen::MatrixXd(jac.D())(2, 2);
    if (k.model == ContactModel::Penalty) {
      EXPECT_EQ(kzz, 1000.0);
      EXPECT_EQ(dzz, 0.3);
    } else {
      EXPECT_NEAR(kzz, 1000.0 * 1e-9 / kLayer, 1e-12);  // kc q / layer
      EXPECT_NEAR(dzz, 0.3 * 1e-9 / kLayer, 1e-15);     // dc w, w = q / layer
    }
  }
}

TEST(ContactWorlds, TheContactExtensionRoundTripsAndBadOnesAreRefused) {
  test::TempDir dir;
  const World plain = test::loadWorld("jello.w");
  EXPECT_EQ(plain.contact, ContactLaw{});  // no extension: the penalty
  World w = plain;
  w.contact = {ContactModel::Smooth, 0.0042};
  const std::string line = "contact smooth 0.0041999999999999997";  // %.17g
  EXPECT_TRUE(w.usesExtensions());
  const auto path = dir.path() / "smooth.w";
  writeWorld(w, path);
  EXPECT_EQ(readWorld(path).contact, w.contact);
  const std::string text = test::readFile(path);
  EXPECT_NE(text.find("\n" + line + "\n"), std::string::npos);
  // A world with the penalty is written without the line: the course's file.
  writeWorld(plain, dir.path() / "plain.w");
  EXPECT_EQ(test::readFile(dir.path() / "plain.w").find("contact"), std::string::npos);

  const auto refused = [&](const std::string& badLine, const std::string& why) {
    std::string bad = text;
    bad.replace(bad.find(line), line.size(), badLine);
    const auto badPath = dir.path() / "bad.w";
    std::ofstream(badPath) << bad;
    try {
      (void)readWorld(badPath);
      ADD_FAILURE() << "accepted: " << badLine;
    } catch (const WorldFileError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.w:"), std::string::npos) << e.what();
    }
  };
  refused("contact sticky", "unknown contact model (known: penalty, smooth, barrier)");
  refused("contact barrier 0.01", "barrier stiffness kappa");
  refused("contact barrier 0 400", "barrier distance dhat");
  refused("contact barrier 0.01 -1", "barrier stiffness kappa");
  refused("contact smooth -0.01", "smooth contact layer");
  refused("contact smooth 0", "smooth contact layer");
  refused("contact smooth", "smooth contact layer");
  refused("contact", "contact model was expected");
  refused("contact penalty contact smooth 0.1", "given twice");
  // Spelled in any case, as integrators are.
  std::string upper = text;
  upper.replace(upper.find("contact smooth"), 14, "contact SMOOTH");
  std::ofstream(dir.path() / "upper.w") << upper;
  EXPECT_EQ(readWorld(dir.path() / "upper.w").contact, w.contact);
}

constexpr double kDhat = 0.05;
const ContactConstants kBarrier{1000.0, 0.3, ContactModel::Barrier, 0.0, kDhat, 800.0};

// Random points of [-2.1, 2.1]^3 outside the model's one solid at a distance in
// [0.2 dhat, 0.9 dhat], away from where the nearest feature changes.
std::vector<Vec3> nearPoints(const Obstacle& o, int count) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.1, 2.1);
  std::vector<Vec3> points;
  Penetration a[kMaxPenetrations], b[kMaxPenetrations];
  for (long tries = 0; int(points.size()) < count && tries < 20000000; ++tries) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    if (o.penetrations(x, kDhat, a) != 1 || a[0].depth > -0.2 * kDhat ||
        a[0].depth < -0.9 * kDhat) {
      continue;
    }
    bool same = true;
    for (const Vec3& d : {Vec3{1e-4, 0, 0}, Vec3{0, 1e-4, 0}, Vec3{0, 0, 1e-4}}) {
      for (double s : {-1.0, 1.0}) {
        same = same && o.penetrations(x + d * s, kDhat, b) == 1 &&
               norm(b[0].gradient - a[0].gradient) < 1e-2;
      }
    }
    if (same) points.push_back(x);
  }
  EXPECT_EQ(int(points.size()), count);
  return points;
}

TEST(BarrierContactLaw, DerivativesAreEachOthersItEndsC2AtDhatAndIsInfiniteAtTheSurface) {
  const double kappa = 800.0, dhat = 0.01;
  for (double d : {1e-5, 1e-3, 0.004, 0.0099}) {
    const double h = 1e-9;
    const ContactLawValue p = barrierContactLaw(-(d + h), kappa, dhat),
                          m = barrierContactLaw(-(d - h), kappa, dhat),
                          c = barrierContactLaw(-d, kappa, dhat);
    // The law is in the depth q = -d: its force is -db/dd, its stiffness d2b/dd2.
    EXPECT_NEAR(-(p.energy - m.energy) / (2 * h), c.force, 1e-6 * std::abs(c.force)) << d;
    EXPECT_NEAR(-(p.force - m.force) / (2 * h), c.stiffness, 1e-5 * c.stiffness) << d;
    EXPECT_GT(c.energy, 0.0);
    EXPECT_GT(c.force, 0.0);      // pushes out
    EXPECT_GT(c.stiffness, 0.0);  // convex: the clamp keeps it
  }
  // Value, slope and curvature all reach 0 at dhat: nothing jumps where it begins.
  const ContactLawValue end = barrierContactLaw(-dhat * (1 - 1e-9), kappa, dhat);
  EXPECT_LT(end.energy, 1e-15);
  EXPECT_LT(end.force, 1e-12);
  EXPECT_LT(end.stiffness, 1e-5 * kappa);
  EXPECT_EQ(barrierContactLaw(-dhat, kappa, dhat).energy, 0.0);
  EXPECT_EQ(barrierContactLaw(-1.0, kappa, dhat).force, 0.0);
  EXPECT_TRUE(std::isinf(barrierContactLaw(0.0, kappa, dhat).energy));
  EXPECT_TRUE(std::isinf(barrierContactLaw(1e-3, kappa, dhat).energy));
  // It grows without bound towards the surface, as -kappa dhat^2 ln(d/dhat) there.
  for (double d : {1e-3, 1e-6, 1e-12}) {
    const double b = barrierContactLaw(-dhat * d, kappa, dhat).energy;
    EXPECT_NEAR(b, -kappa * dhat * dhat * std::log(d), 2.5e-3 * b) << d;
  }
}

TEST(BarrierContact, ForcesAndJacobiansMatchFiniteDifferencesOutsideEverySolid) {
  for (const ModelSpec& spec : everySolid(kBarrier)) {
    const Model model(spec);
    const Obstacle& o = *model.obstacles()[0];
    SCOPED_TRACE(std::string(obstacleName(o.kind())));
    for (const Vec3& x : nearPoints(o, 12)) {
      expectConsistent(model, x);
      // The barrier has no damping: D is 0.
      JacobianAssembler jac(model);
      jac.assemble(at(x, {0.4, -0.7, 0.3}).x.data(), {});
      EXPECT_EQ(Eigen::MatrixXd(jac.D()).cwiseAbs().maxCoeff(), 0.0);
    }
  }
}

TEST(BarrierContact, ForcesAndJacobiansMatchFiniteDifferencesWithinDhatOfTwoOrThreeSolids) {
  ModelSpec spec = onePoint(kBarrier);
  spec.walls = true;
  spec.plane = Plane{0, 0, 1, 1.95};  // the floor raised 5 cm
  spec.sphere = Sphere{{0.0, 0.0, 0.0}, 1.0};
  const Model model(spec);
  for (const Vec3& x : {Vec3{1.98, -1.97, 0.5},   // two walls
                        Vec3{1.97, 1.99, -1.92},  // two walls and the plane
                        Vec3{0.0, 0.6, 0.82}}) {  // the sphere, 1.6 cm out
    Penetration touch[kMaxPenetrations];
    int total = 0;
    for (const auto& o : model.obstacles()) total += o->penetrations(x, kDhat, touch);
    EXPECT_GE(total, x.x == 0.0 ? 1 : 2);
    expectConsistent(model, x);
  }
}

// The cone's distance outside: no point of its surface is nearer (a brute-force search over
// surface points made by projecting random points), and x - D grad(D) lies on the surface.
TEST(BarrierContact, TheConesExteriorDistanceIsExact) {
  const Cone cone{{0.2, -0.1, 0.0}, {0.1, 0.2, -1.0}, 1.8, 1.1};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  std::vector<Vec3> surface;
  std::vector<Vec3> outside;
  while (surface.size() < 20000) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    if (conePenetration(cone, x)) continue;
    const Penetration p = coneExterior(cone, x);
    const Vec3 foot = x + p.gradient * (-p.depth);  // x - D grad(D), grad(D) = -gradient
    EXPECT_NEAR(norm(p.gradient), 1.0, 1e-12);
    // The foot is on the surface: just inside it along the normal, outside just beyond.
    const Vec3 in = foot + p.gradient * 1e-9, out = foot - p.gradient * 1e-9;
    EXPECT_TRUE(conePenetration(cone, in).has_value() || coneExterior(cone, in).depth > -2e-9);
    EXPECT_NEAR(coneExterior(cone, out).depth, -1e-9, 1e-12);
    surface.push_back(foot);
    if (outside.size() < 200) outside.push_back(x);
  }
  for (const Vec3& x : outside) {
    const double D = -coneExterior(cone, x).depth;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& q : surface) nearest = std::min(nearest, norm(x - q));
    EXPECT_LE(D, nearest + 1e-12);
    EXPECT_GE(D, nearest - 0.05);  // the sampled surface is dense to a few cm
  }
}

// The spiral's distance outside is a lower bound on the true one, and close to it near the
// ramp: against a brute-force search over points of the solid (a grid of its turns, radii and
// thickness, 1-2.5 cm apart on its surface), never above the nearest, and for points within
// 10 cm at least 1/sqrt(2) of it less the grid's spacing (a point off an edge is as far from
// each of its two faces as 1/sqrt(2) of its distance to the edge). 0 on the surface.
TEST(BarrierContact, TheSpiralsExteriorDistanceIsALowerBoundCloseToTheTrueOne) {
  const Spiral s{0.1, -0.2, 1.0, 0.4, 1.6, 1.2, 1.5, 0.3};
  const double c = s.pitch / (2.0 * std::numbers::pi), span = 2.0 * std::numbers::pi * s.turns;
  std::vector<Vec3> solid;  // its surface's points (the nearest solid point is on it)
  const int nTheta = 1500, nR = 60, nT = 12;
  for (int i = 0; i <= nTheta; ++i) {
    const double big = span * i / nTheta;
    for (int j = 0; j <= nR; ++j) {
      const double r = s.rInner + (s.rOuter - s.rInner) * j / nR;
      for (int k = 0; k <= nT; ++k) {
        const bool face = i == 0 || i == nTheta || j == 0 || j == nR || k == 0 || k == nT;
        if (!face) continue;
        const double z = s.zTop - c * big - s.thickness * k / nT;
        solid.push_back({s.cx + r * std::cos(big), s.cy + r * std::sin(big), z});
      }
    }
  }
  const double spacing = 0.025;  // the grid's largest gap: the thickness's 0.3 / 12
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  int near = 0, checked = 0;
  while (checked < 300) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    if (spiralPenetration(s, x)) continue;
    const double D = -spiralExterior(s, x).depth;
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& q : solid) nearest = std::min(nearest, norm(x - q));
    if (nearest > 0.4) continue;
    ++checked;
    EXPECT_GT(D, 0.0) << x.x << " " << x.y << " " << x.z;
    EXPECT_LE(D, nearest + 1e-12) << std::setprecision(17) << x.x << " " << x.y << " " << x.z;
    if (nearest < 0.1) {
      ++near;
      EXPECT_GE(D, nearest / std::sqrt(2.0) - spacing) << x.x << " " << x.y << " " << x.z;
    }
  }
  EXPECT_GT(near, 30);
  // A hair above the top, at most that hair and more than half of it (the slope's factor, 0.55
  // here); a hair beyond the rim, exactly it.
  const double mid = 0.5 * (s.rInner + s.rOuter);
  const Vec3 onTop{s.cx + mid * std::cos(2.0), s.cy + mid * std::sin(2.0), s.zTop - c * 2.0};
  const double hair = -spiralExterior(s, onTop + Vec3{0, 0, 1e-6}).depth;
  EXPECT_LE(hair, 1e-6);
  EXPECT_GT(hair, 0.5e-6);
  const Vec3 onRim{s.cx + s.rOuter * std::cos(1.0), s.cy + s.rOuter * std::sin(1.0),
                   s.zTop - c * 1.0 - 0.1};
  EXPECT_NEAR(spiralExterior(s, onRim + Vec3{std::cos(1.0), std::sin(1.0), 0} * 1e-6).depth, -1e-6,
              1e-9);
}

// No point starting outside, moved by a step bound's fraction of any update, ends inside; for
// the walls, the plane and the sphere the bound is the exact time of impact.
TEST(BarrierContact, StepBoundsNeverLetAPointIn) {
  for (const ModelSpec& spec : everySolid(kBarrier)) {
    const Model model(spec);
    const Obstacle& o = *model.obstacles()[0];
    SCOPED_TRACE(std::string(obstacleName(o.kind())));
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.95, 1.95), m(-3.0, 3.0);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 x{u(rng), u(rng), u(rng)}, dx{m(rng), m(rng), m(rng)};
      if (!(o.signedDistance(x) > 0.0)) continue;
      const double s = o.stepBound(x, dx);
      ASSERT_GE(s, 0.0);
      ASSERT_LE(s, 1.0);
      for (double t = 0.0; t <= 1.0; t += 1.0 / 64) {
        EXPECT_GT(o.signedDistance(x + dx * (0.999 * s * t)), 0.0);
      }
      if (s < 1.0) {
        ++hits;
        // At the bound the point is at the surface; the cone's and the spiral's advancements
        // stop short of it, by at most 1 mm where the path grazes the surface (200
        // advancements).
        const double left = o.signedDistance(x + dx * s);
        const bool advanced = o.kind() == ObstacleKind::Cone || o.kind() == ObstacleKind::Spiral;
        EXPECT_GE(left, -1e-12);  // exactly at the surface, to round-off
        EXPECT_LT(left, advanced ? 1e-3 : 1e-12);
      }
    }
    EXPECT_GT(hits, 100);  // the case is exercised
  }
}

TEST(BarrierContact, WorldsWithAPointInsideAreRefusedAndTheExtensionRoundTrips) {
  World w = test::loadWorld("jello.w");
  w.contact = {ContactModel::Barrier, 0.0, 0.002, 350.0};
  test::TempDir dir;
  writeWorld(w, dir.path() / "b.w");
  EXPECT_EQ(readWorld(dir.path() / "b.w").contact, w.contact);
  EXPECT_NE(test::readFile(dir.path() / "b.w").find("\ncontact barrier 0.002 350\n"),
            std::string::npos);
  const Model fine(w);
  EXPECT_FALSE(fine.startProblem(initialState(w)).has_value());

  // A spiral is held like every solid (it was refused while it had no exterior distance).
  World spiral = w;
  spiral.spiral = Spiral{0.1, -0.2, -0.6, 0.4, 1.6, 0.5, 1.0, 0.2};  // under the cube
  spiral.plane.reset();
  EXPECT_FALSE(Model(spiral).startProblem(initialState(spiral)).has_value());

  World inside = w;
  inside.sphere = Sphere{{0.5, 0.5, 0.5}, 0.3};  // around the cube's centre
  const std::string in = Model(inside).startProblem(initialState(inside)).value().message;
  EXPECT_NE(in.find("is inside the sphere"), std::string::npos) << in;
  // Simulation refuses to step it rather than compute infinite forces.
  Simulation sim(inside);
  const StepResult r = sim.step();
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("inside the sphere"), std::string::npos) << r.message;
}

// A start no step can begin from (issue 41, item 5): a cube deep inside a sphere of radius
// 1e308, or under a plane 1e300 m off, has an infinite contact energy; implicit, midpoint, bdf2
// and newmark simulated it as if the solid were not there. It is refused on load, naming the
// line that set the solid, and no integrator steps it.
TEST(StartCheck, AStartWhoseEnergyIsNotFiniteIsRefusedNamingTheLine) {
  test::TempDir dir;
  const std::string jello = test::readFile(std::filesystem::path(JELLO_WORLDS_DIR) / "jello.w");
  const auto lineCount = [](const std::string& text) {
    return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  };
  {
    const std::filesystem::path path = dir.path() / "deep.w";
    std::ofstream(path) << jello << "sphere 0 0 -1 1e308\n";
    const World w = readWorld(path);
    try {
      checkStart(w, path.string());
      ADD_FAILURE() << "a cube inside a sphere of radius 1e308 was accepted";
    } catch (const WorldFileError& e) {
      EXPECT_EQ(e.line(), lineCount(jello) + 1) << e.what();
      EXPECT_EQ(e.token(), "sphere");
      EXPECT_NE(std::string(e.what()).find("sphere's contact energy at the start is inf"),
                std::string::npos)
          << e.what();
    }
    for (IntegratorKind kind : allIntegrators()) {
      Simulation sim(w, kind);
      const StepResult r = sim.step();
      EXPECT_FALSE(r.ok) << integratorName(kind);
      EXPECT_NE(r.message.find("every term of the energy must be finite"), std::string::npos)
          << integratorName(kind) << ": " << r.message;
    }
  }
  {
    World w = test::loadWorld("jello.w");
    w.plane = Plane{0.0, 0.0, 1.0, -1e300};  // free only above z = 1e300
    const std::filesystem::path path = dir.path() / "under.w";
    writeWorld(w, path);
    const World back = readWorld(path);
    const std::optional<StartProblem> problem = Model(back).startProblem(initialState(back));
    ASSERT_TRUE(problem.has_value());
    EXPECT_EQ(problem->what, "plane");
    const WorldFileError e = startError(*problem, back, path.string());
    ASSERT_NE(back.sourceOf("plane"), nullptr);
    EXPECT_EQ(e.line(), back.sourceOf("plane")->line);
    EXPECT_GT(e.line(), 3);
  }
  // Every reference world starts finite.
  for (const char* name : {"jello.w", "showcase.w", "sphere-drop.w", "stiff-k1e4.w"}) {
    const World w = test::loadWorld(name);
    EXPECT_FALSE(Model(w).startProblem(initialState(w)).has_value()) << name;
  }
}

}  // namespace
}  // namespace jello
