// The cube's surface as the viewer draws it: the lattice points on the outside, two triangles
// per surface quad (wound counter-clockwise seen from outside), per-vertex normals averaged
// from the triangles around each point, and the springs whose both ends lie on the surface
// (the only ones the wireframe shows, as in the original assignment).
#pragma once

#include <array>
#include <vector>

#include "src/effects/spring_forces.h"
#include "src/state.h"
#include "src/world/lattice.h"

namespace jello::viewer {

struct SurfaceMesh {
  int n = 0;                                  // points per axis
  std::vector<int> points;                    // lattice indices of the surface points
  std::vector<std::array<int, 3>> triangles;  // lattice indices, outward winding at rest
  // Texture coordinates of each triangle's corners: the face's two free lattice indices over
  // N - 1, so each face of the cube shows the whole texture once.
  std::vector<std::array<std::array<float, 2>, 3>> uv;
};

bool onSurface(const Lattice& lattice, int index);
SurfaceMesh surfaceMesh(const Lattice& lattice);

// Unit normals for every lattice point (zero for interior points) at the state's positions.
// Degenerate triangles (a crushed cube) contribute nothing, so no normal is NaN.
std::vector<Vec3> vertexNormals(const SurfaceMesh& mesh, const State& state);

// The springs with both ends on the surface.
std::vector<Spring> surfaceSprings(const std::vector<Spring>& springs, const Lattice& lattice);

}  // namespace jello::viewer
