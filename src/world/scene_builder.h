// Shared scene builders: the world creator's presets, and resampling a world's cube to another
// resolution. Tests, benchmarks, experiments and the viewer build their scenes here too.
#pragma once

#include <optional>

#include "src/world/world.h"

namespace jello {

enum class PosePreset {
  Rest,          // (i,j,k)/(N-1): the unit cube [0,1]^3
  SkewedCorner,  // rest, with the far corner pulled out by one spacing (the original default)
  Stretched,     // rest, stretched along x about the cube's centre
  Rotated,       // rest, rotated about an axis through the cube's centre
  Translated,    // rest, moved
};

enum class FieldPreset {
  None,     // zero force at every node (the original default), or no field at resolution 0
  Gravity,  // F = (0, 0, -s)
  Vortex,   // F = s (-y, x, 0): rotate.w's field with s = 5/512
  Radial,   // F = -s (x, y, z): a linear pull to the box centre, exact under interpolation
};

struct SceneSpec {
  IntegratorKind integrator = IntegratorKind::RK4;
  double dt = 0.0005;  // s
  int stepsPerFrame = 1;
  double kElastic = 200.0, dElastic = 0.25;      // N/m, N*s/m
  double kCollision = 400.0, dCollision = 0.25;  // N/m, N*s/m
  ContactLaw contact;                            // penalty
  double mass = 1.0 / 512;                       // kg per point
  std::optional<Plane> plane = Plane{-1.0, 1.0, 1.0, 2.0};
  FieldPreset field = FieldPreset::None;
  double fieldStrength = 0.0;  // N (Radial, Vortex: N/m)
  int fieldResolution = 30;    // 0 = no field
  int cubeResolution = kDefaultCubeResolution;
  PosePreset pose = PosePreset::SkewedCorner;
  double stretch = 1.25;             // Stretched: factor along x
  double rotateDegrees = 30.0;       // Rotated: angle, degrees
  Vec3 rotateAxis{1.0, 1.0, 1.0};    // Rotated: axis (any length, not zero)
  Vec3 translate{0.5, 0.5, 0.5};     // Translated: offset, m
  Vec3 velocity{10.0, -10.0, 20.0};  // m/s, uniform
  double spin = 0.0;  // rad/s about the z axis through the cube's centre, added to velocity
  std::optional<Sphere> sphere;
  std::optional<Cone> cone;
  std::optional<Spiral> spiral;
};

// The defaults above are the original course creator's: SceneSpec{} builds createWorld's jello.w.
World buildWorld(const SceneSpec& spec);

// A stiff cube for stability studies: spring stiffness k (N/m), the reference worlds' damping
// 0.25 N*s/m, far corner pulled out by one spacing, at rest, no plane, no field: nothing but
// its own springs (and the walls, never reached).
SceneSpec stiffCube(double k);

// The stiff cube for accuracy and cost studies: stiffCube(k) stretched 5% along x and spinning
// at 2 rad/s, so its energy sits in smooth, mostly low modes (stiffCube's pulled corner strains
// one spring 100% and is violently nonlinear at high k).
SceneSpec vibratingStiffCube(double k);

// Default strength of a field preset (N): the value rotate.w / gravity.w use, scaled by mass.
double defaultFieldStrength(FieldPreset preset, double mass);

// The same world with an n^3 cube: initial positions and velocities are interpolated
// trilinearly in lattice coordinates, so the deformation and motion keep their shape.
World resampleCube(const World& world, int n);

}  // namespace jello
