#include "src/world/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "src/base/assertions.h"
#include "src/world/lattice.h"

namespace jello {
namespace {

Vec3 rotate(const Vec3& v, Vec3 axis, double radians) {
  axis = unitVector(axis);  // robust to axes like (1e200, 1e200, 0) or (1e-200, 0, 0)
  const double c = std::cos(radians), s = std::sin(radians);
  // Rodrigues' rotation formula.
  return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1.0 - c));
}

Vec3 posed(const SceneSpec& spec, Vec3 rest) {
  const Vec3 centre{0.5, 0.5, 0.5};
  switch (spec.pose) {
    case PosePreset::Rest:
    case PosePreset::SkewedCorner:
      return rest;
    case PosePreset::Stretched:
      return {centre.x + (rest.x - centre.x) * spec.stretch, rest.y, rest.z};
    case PosePreset::Rotated:
      return centre +
             rotate(rest - centre, spec.rotateAxis, spec.rotateDegrees * std::numbers::pi / 180.0);
    case PosePreset::Translated:
      return rest + spec.translate;
  }
  return rest;
}

Vec3 fieldAt(FieldPreset preset, double s, const Vec3& x) {
  switch (preset) {
    case FieldPreset::None:
      return {};
    case FieldPreset::Gravity:
      return {0.0, 0.0, -s};
    case FieldPreset::Vortex:
      return {-s * x.y, s * x.x, 0.0};
    case FieldPreset::Radial:
      return x * -s;
  }
  return {};
}

}  // namespace

SceneSpec stiffCube(double k) {
  SceneSpec spec;
  spec.kElastic = k;
  spec.plane.reset();
  spec.fieldResolution = 0;
  spec.velocity = {};
  return spec;
}

SceneSpec vibratingStiffCube(double k) {
  SceneSpec spec = stiffCube(k);
  spec.pose = PosePreset::Stretched;
  spec.stretch = 1.05;
  spec.spin = 2.0;
  return spec;
}

double defaultFieldStrength(FieldPreset preset, double mass) {
  switch (preset) {
    case FieldPreset::None:
      return 0.0;
    case FieldPreset::Gravity:
      return 9.81 * mass;  // N
    case FieldPreset::Vortex:
      return 5.0 * mass;  // N/m: rotate.w's 5/512 at mass 1/512
    case FieldPreset::Radial:
      return 25.0 * mass;  // N/m
  }
  return 0.0;
}

World buildWorld(const SceneSpec& spec) {
  World w;
  w.integrator = spec.integrator;
  w.dt = spec.dt;
  w.stepsPerFrame = spec.stepsPerFrame;
  w.kElastic = spec.kElastic;
  w.dElastic = spec.dElastic;
  w.kCollision = spec.kCollision;
  w.contact = spec.contact;
  w.dCollision = spec.dCollision;
  w.mass = spec.mass;
  w.plane = spec.plane;
  w.sphere = spec.sphere;
  w.cone = spec.cone;
  w.spiral = spec.spiral;
  w.cubeResolution = spec.cubeResolution;

  const int r = spec.fieldResolution;
  if (r > 0) {
    w.field.resolution = r;
    w.field.forces.reserve(static_cast<std::size_t>(r) * r * r);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < r; ++j)
        for (int k = 0; k < r; ++k) {
          const Vec3 node{-2.0 + 4.0 * i / (r - 1), -2.0 + 4.0 * j / (r - 1),
                          -2.0 + 4.0 * k / (r - 1)};
          w.field.forces.push_back(fieldAt(spec.field, spec.fieldStrength, node));
        }
  }

  const Lattice lat{spec.cubeResolution};
  const Vec3 centre{0.5, 0.5, 0.5};
  for (int i = 0; i < lat.n; ++i)
    for (int j = 0; j < lat.n; ++j)
      for (int k = 0; k < lat.n; ++k) {
        Vec3 x = posed(spec, lat.restPosition(i, j, k));
        if (spec.pose == PosePreset::SkewedCorner && i == lat.n - 1 && j == lat.n - 1 &&
            k == lat.n - 1) {
          const double h = lat.spacing();
          x = x + Vec3{h, h, h};
        }
        const Vec3 r0 = x - centre;
        w.positions.push_back(x);
        w.velocities.push_back(spec.velocity + Vec3{-spec.spin * r0.y, spec.spin * r0.x, 0.0});
      }
  return w;
}

World resampleCube(const World& world, int n) {
  JELLO_ASSERT(n >= 2, "a cube has at least 2 points per edge");
  const int m = world.cubeResolution;
  if (n == m) return world;
  const Lattice from{m};
  auto sample = [&](const std::vector<Vec3>& values, double s, double t, double u) {
    // Lattice coordinates in [0, m-1]; trilinear over the enclosing cell.
    auto split = [m](double c, int& i, double& f) {
      i = std::min(static_cast<int>(c), m - 2);
      f = c - i;
    };
    int i, j, k;
    double fi, fj, fk;
    split(s, i, fi);
    split(t, j, fj);
    split(u, k, fk);
    Vec3 sum;
    for (int di = 0; di < 2; ++di)
      for (int dj = 0; dj < 2; ++dj)
        for (int dk = 0; dk < 2; ++dk) {
          const double wgt = (di ? fi : 1 - fi) * (dj ? fj : 1 - fj) * (dk ? fk : 1 - fk);
          sum += values[from.index(i + di, j + dj, k + dk)] * wgt;
        }
    return sum;
  };
  World w = world;
  w.cubeResolution = n;
  w.positions.clear();
  w.velocities.clear();
  const double scale = double(m - 1) / (n - 1);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        w.positions.push_back(sample(world.positions, i * scale, j * scale, k * scale));
        w.velocities.push_back(sample(world.velocities, i * scale, j * scale, k * scale));
      }
  return w;
}

}  // namespace jello
