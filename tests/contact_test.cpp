// Penalty contact: direction, magnitude, and consistency with its energy.
#include "src/effects/contact.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "src/world/scene_builder.h"

namespace jello {
namespace {

constexpr ContactConstants kContact{400.0, 0.25};

// One point at x with velocity v; returns the contact force of `c`.
template <class Contact>
Vec3 forceOn(const Contact& c, Vec3 x, Vec3 v = {}) {
  const double xs[3] = {x.x, x.y, x.z}, vs[3] = {v.x, v.y, v.z};
  double f[3] = {0, 0, 0};
  c.accumulate(xs, vs, f, 1);
  return {f[0], f[1], f[2]};
}

template <class Contact>
double energyAt(const Contact& c, Vec3 x) {
  const double xs[3] = {x.x, x.y, x.z};
  return c.energy(xs, 1);
}

// Central differences of the energy: the force must be minus its gradient.
template <class Contact>
void expectForceIsMinusEnergyGradient(const Contact& c, Vec3 x) {
  const Vec3 f = forceOn(c, x);
  const double h = 1e-7;
  const Vec3 e[3] = {{h, 0, 0}, {0, h, 0}, {0, 0, h}};
  const double fd[3] = {-(energyAt(c, x + e[0]) - energyAt(c, x - e[0])) / (2 * h),
                        -(energyAt(c, x + e[1]) - energyAt(c, x - e[1])) / (2 * h),
                        -(energyAt(c, x + e[2]) - energyAt(c, x - e[2])) / (2 * h)};
  EXPECT_NEAR(f.x, fd[0], 1e-6 * (1 + norm(f)));
  EXPECT_NEAR(f.y, fd[1], 1e-6 * (1 + norm(f)));
  EXPECT_NEAR(f.z, fd[2], 1e-6 * (1 + norm(f)));
}

TEST(WallContact, PushesEachOfTheSixWallsBackInside) {
  const WallContact walls(kContact);
  const double depth = 0.01;
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.0, 1.0}) {
      double c[3] = {0.5, -0.5, 0.25};
      c[axis] = side * (kBoxHalfSize + depth);
      const Vec3 f = forceOn(walls, {c[0], c[1], c[2]});
      const double fc[3] = {f.x, f.y, f.z};
      EXPECT_NEAR(fc[axis], -side * kContact.stiffness * depth, 1e-12);
      EXPECT_EQ(fc[(axis + 1) % 3], 0.0);
      EXPECT_EQ(fc[(axis + 2) % 3], 0.0);
    }
  }
}

TEST(WallContact, ACornerGetsOneSpringPerViolatedWall) {
  const WallContact walls(kContact);
  const Vec3 f = forceOn(walls, {2.1, -2.2, 2.05});
  EXPECT_NEAR(f.x, -400.0 * 0.1, 1e-12);
  EXPECT_NEAR(f.y, 400.0 * 0.2, 1e-12);
  EXPECT_NEAR(f.z, -400.0 * 0.05, 1e-12);
  expectForceIsMinusEnergyGradient(walls, {2.1, -2.2, 2.05});
}

TEST(WallContact, DampsOnlyPenetratingPointsAlongTheNormal) {
  const WallContact walls(kContact);
  EXPECT_EQ(forceOn(walls, {1.9, 0, 0}, {5, 5, 5}), (Vec3{0, 0, 0}));
  const Vec3 f = forceOn(walls, {2.0 + 1e-3, 0, 0}, {5, 7, 9});
  EXPECT_DOUBLE_EQ(f.x, -400.0 * ((2.0 + 1e-3) - 2.0) - 0.25 * 5);
  EXPECT_EQ(f.y, 0.0);
}

TEST(WallContact, AllInsideSeesAnyPointOutside) {
  Eigen::VectorXd x = Eigen::VectorXd::Constant(30, 1.0);
  EXPECT_TRUE(WallContact::allInside(x.data(), 10));
  x[17] = -2.0001;
  EXPECT_FALSE(WallContact::allInside(x.data(), 10));
}

TEST(PlaneContact, PushesTowardTheFreeSideAlongTheNormal) {
  // jello.w's plane -x + y + z + 2 = 0, free where positive.
  const PlaneContact plane(Plane{-1, 1, 1, 2}, kContact);
  const Vec3 n = plane.normal();
  EXPECT_NEAR(norm(n), 1.0, 1e-15);
  const Vec3 onPlane{2.0, 0.0, 0.0};  // -2 + 0 + 0 + 2 = 0
  const Vec3 solid = onPlane - n * 0.02;
  const Vec3 f = forceOn(plane, solid);
  EXPECT_NEAR(dot(f, n), 400.0 * 0.02, 1e-9);
  EXPECT_NEAR(norm(f - n * dot(f, n)), 0.0, 1e-12);
  EXPECT_EQ(forceOn(plane, onPlane + n * 0.02), (Vec3{0, 0, 0}));
  expectForceIsMinusEnergyGradient(plane, solid);
}

TEST(PlaneContact, ExtremeNormalsGiveTheSamePlane) {
  // Scaling a, b, c, d by any positive factor is the same plane: from 1e-300 (whose squares
  // underflow) to 1e300 (whose squares overflow).
  const PlaneContact reference(Plane{-1, 1, 1, 2}, kContact);
  for (double s : {1e-300, 1e-170, 1e-160, 1e150, 1e160, 1e300}) {
    const PlaneContact plane(Plane{-s, s, s, 2 * s}, kContact);
    EXPECT_NEAR(norm(plane.normal() - reference.normal()), 0.0, 1e-15) << s;
    EXPECT_NEAR(plane.offset(), reference.offset(), 1e-15) << s;
  }
}

TEST(Vec3, UnitVectorOfHugeAndTinyVectors) {
  EXPECT_NEAR(norm(unitVector({1e200, 1e200, 0}) - Vec3{M_SQRT1_2, M_SQRT1_2, 0}), 0.0, 1e-15);
  EXPECT_NEAR(norm(unitVector({1e-310, 0, 0}) - Vec3{1, 0, 0}), 0.0, 1e-15);  // subnormal
  EXPECT_TRUE(std::isnan(unitVector({0, 0, 0}).x));
}

TEST(SceneBuilder, AHugeRotationAxisRotatesLikeAUnitOne) {
  // jello-create-world --axis 1e200 1e200 0 used to shrink the cube (|axis|^2 overflowed).
  SceneSpec unit, huge;
  unit.pose = huge.pose = PosePreset::Rotated;
  unit.rotateAxis = {1, 1, 0};
  huge.rotateAxis = {1e200, 1e200, 0};
  const World a = buildWorld(unit), b = buildWorld(huge);
  double worst = 0.0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    worst = std::max(worst, norm(a.positions[i] - b.positions[i]));
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(SphereContact, PushesRadiallyOut) {
  const SphereContact sphere(Sphere{{0, 0, -1}, 0.5}, kContact);
  const Vec3 x{0.1, 0.2, -0.8};
  const Vec3 r = x - Vec3{0, 0, -1};
  const Vec3 f = forceOn(sphere, x);
  const double depth = 0.5 - norm(r);
  EXPECT_NEAR(norm(f), 400.0 * depth, 1e-9);
  EXPECT_NEAR(dot(f, r) / (norm(f) * norm(r)), 1.0, 1e-12);
  EXPECT_EQ(forceOn(sphere, {0, 0, 0}), (Vec3{0, 0, 0}));
  expectForceIsMinusEnergyGradient(sphere, x);
}

}  // namespace
}  // namespace jello
