// The whole initial state of one jello scene, as a world file holds it (worlds/FORMAT.md). A
// World is plain data; loading checks it, building a Model turns it into effects.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "src/base/vec3.h"
#include "src/world/contact_law.h"
#include "src/world/integrator_table.h"

namespace jello {

// Inclined plane a*x + b*y + c*z + d = 0. The side where a*x+b*y+c*z+d > 0 is free space, the
// other side is solid (the cube starts on the positive side in every reference world).
struct Plane {
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0;  // a,b,c: normal (any length, not zero); d: m*|n|
};

// Solid sphere obstacle (world-file extension `sphere`).
struct Sphere {
  Vec3 center;          // m
  double radius = 0.0;  // m, > 0
};

// Solid right circular cone (world-file extension `cone`): apex, axis direction from the apex
// towards the base (any non-zero length), height and base radius.
struct Cone {
  Vec3 apex;            // m
  Vec3 axis;            // non-zero; the reader keeps it as written
  double height = 0.0;  // m, > 0
  double radius = 0.0;  // m, > 0, of the base disk

  bool operator==(const Cone&) const = default;
};

// Solid spiral ramp (world-file extension `spiral`): a slab of thickness `thickness` below a
// helicoid around the vertical axis through (cx, cy), between radii rInner and rOuter, whose top
// descends by `pitch` per turn counter-clockwise from height zTop at angle 0 (the +x direction)
// through `turns` turns.
struct Spiral {
  double cx = 0.0, cy = 0.0;  // m
  double zTop = 0.0;          // m
  double rInner = 0.0;        // m, >= 0
  double rOuter = 0.0;        // m, > rInner
  double pitch = 0.0;         // m per turn, > thickness
  double turns = 0.0;         // > 0
  double thickness = 0.0;     // m, > 0

  bool operator==(const Spiral&) const = default;
};

// Force field sampled on res^3 nodes covering the box [-2,2]^3; node (i,j,k) has flat index
// i*res*res + j*res + k. resolution 0 means no field.
struct ForceField {
  int resolution = 0;
  std::vector<Vec3> forces;  // N per node

  bool empty() const { return resolution == 0; }
};

inline constexpr int kDefaultCubeResolution = 8;
// m: no point may start farther from the origin (the box is [-2,2]^3). The simulation's
// divergence bound (solvers/simulation.h) is the same distance.
inline constexpr double kStartBound = 100.0;  // the only one the original format knows

// Where the reader found a setting a later check may refuse (Model::startProblem): its name
// ("kElastic", "kCollision", "plane", "sphere", "cone", "spiral", "contact"), line and token.
struct SourcePlace {
  std::string what;
  int line = 0;
  std::string token;
};

struct World {
  IntegratorKind integrator = IntegratorKind::RK4;
  // The file's integrator name when it was not one of ours and the reader was told to accept
  // it (ReaderLimits::acceptUnknownIntegrator); empty otherwise. Never written back.
  std::string unknownIntegrator;
  double dt = 0.0005;       // s, time step
  int stepsPerFrame = 1;    // n: integrator steps per drawn frame
  double kElastic = 0.0;    // N/m, structural, shear and bend springs
  double dElastic = 0.0;    // N*s/m, their damping along the spring
  double kCollision = 0.0;  // N/m, contact penalty springs (walls, plane, sphere)
  double dCollision = 0.0;  // N*s/m, their damping along the contact normal
  ContactLaw contact;       // extension `contact`: how contact rises with depth (penalty: as ever)
  double mass = 1.0 / 512;  // kg, of EACH point
  std::optional<Plane> plane;
  ForceField field;
  int cubeResolution = kDefaultCubeResolution;  // N: N^3 points, spacing 1/(N-1)
  std::vector<Vec3> positions;   // m, N^3 entries, point (i,j,k) at index i*N*N + j*N + k
  std::vector<Vec3> velocities;  // m/s, N^3 entries
  std::optional<Sphere> sphere;
  std::optional<Cone> cone;
  std::optional<Spiral> spiral;
  // The file's places of the settings above, in reading order; empty for a world not read from
  // a file. Never written back.
  std::vector<SourcePlace> sources;

  int numPoints() const { return cubeResolution * cubeResolution * cubeResolution; }
  // True when a file of this world needs the extension block (so the original loader would
  // not read it as written).
  // The place the reader recorded for `what`, or null.
  const SourcePlace* sourceOf(std::string_view what) const {
    for (const SourcePlace& p : sources) {
      if (p.what == what) return &p;
    }
    return nullptr;
  }
  bool usesExtensions() const {
    return cubeResolution != kDefaultCubeResolution || sphere.has_value() || cone.has_value() ||
           spiral.has_value() || contact.model != ContactModel::Penalty ||
           !contact.frictionIsDefault() ||
           (integrator != IntegratorKind::Euler && integrator != IntegratorKind::RK4);
  }
};

}  // namespace jello
