// Trilinear interpolation of the force field.
#include "src/effects/force_field.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

Vec3 affine(const Vec3& x) {
  return {0.3 + 1.5 * x.x - 0.2 * x.y + 0.7 * x.z, -0.1 * x.x + 2.0 * x.y,
          -0.5 + 0.25 * x.z - 0.9 * x.x};
}

ForceField sampled(int r, Vec3 (*f)(const Vec3&)) {
  ForceField field;
  field.resolution = r;
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < r; ++j)
      for (int k = 0; k < r; ++k)
        field.forces.push_back(
            f({-2.0 + 4.0 * i / (r - 1), -2.0 + 4.0 * j / (r - 1), -2.0 + 4.0 * k / (r - 1)}));
  return field;
}

void expectNear(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(FieldForces, InterpolationIsExactOnAffineFields) {
  const FieldForces field(sampled(7, affine));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 x{u(rng), u(rng), u(rng)};
    expectNear(field.sample(x), affine(x), 1e-13);
  }
}

TEST(FieldForces, EqualsTheNodeValuesAtTheNodes) {
  auto bumpy = [](const Vec3& x) {
    return Vec3{std::sin(3 * x.x * x.y), x.z * x.z * x.x, std::cos(x.y + 2 * x.z)};
  };
  const int r = 5;
  const ForceField grid = sampled(r, bumpy);
  const FieldForces field(grid);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < r; ++j)
      for (int k = 0; k < r; ++k) {
        const Vec3 node{-2.0 + 4.0 * i / (r - 1), -2.0 + 4.0 * j / (r - 1),
                        -2.0 + 4.0 * k / (r - 1)};
        expectNear(field.sample(node), grid.forces[(i * r + j) * r + k], 1e-14);
      }
}

TEST(FieldForces, ClampsPointsOutsideTheBoxToItsSurface) {
  const FieldForces field(sampled(4, affine));
  expectNear(field.sample({3.0, -5.0, 0.5}), affine({2.0, -2.0, 0.5}), 1e-13);
  expectNear(field.sample({-2.5, 0.1, 9.0}), affine({-2.0, 0.1, 2.0}), 1e-13);
}

TEST(FieldForces, ANonFinitePositionReadsTheBoxInsteadOfCrashing) {
  const FieldForces field(sampled(4, affine));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expectNear(field.sample({nan, 0.5, -inf}), affine({-2.0, 0.5, -2.0}), 1e-13);
  expectNear(field.sample({inf, nan, nan}), affine({2.0, -2.0, -2.0}), 1e-13);
  double gradient[3][3];
  field.gradient({nan, nan, nan}, gradient);
  EXPECT_TRUE(std::isfinite(gradient[0][0]));
}

TEST(FieldForces, RecognizesUniformAndZeroFields) {
  EXPECT_TRUE(FieldForces(test::loadWorld("gravity.w").field).isUniform());
  EXPECT_TRUE(FieldForces(test::loadWorld("jello.w").field).isZero());
  EXPECT_FALSE(FieldForces(test::loadWorld("rotate.w").field).isUniform());
}

TEST(FieldForces, RotateWorldFieldIsTheVortexBetweenNodes) {
  // rotate.w's field is linear in x and y, so interpolation reproduces it to print precision.
  const FieldForces field(test::loadWorld("rotate.w").field);
  const Vec3 x{0.37, -1.21, 0.9};
  expectNear(field.sample(x), Vec3{-5.0 / 512 * x.y, 5.0 / 512 * x.x, 0.0}, 1e-6);
}

}  // namespace
}  // namespace jello
