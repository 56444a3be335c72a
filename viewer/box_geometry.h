// Geometry of what the viewer draws around the cube: the inclined plane clipped to the box
// [-2,2]^3 and the force field's arrows.
//   plane polygon: the points where a x + b y + c z + d = 0 meets the box's 12 edges, ordered
//   by angle around their centroid in the plane (a convex polygon of 3 to 6 corners).
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "src/world/world.h"

namespace jello::viewer {

// The box's 12 edges, as (start, end) pairs.
std::array<std::pair<Vec3, Vec3>, 12> boxEdges();
// The box's floor (z = -2), its corners counter-clockwise seen from above.
std::vector<Vec3> floorCorners();

// The plane's part inside the box, corners in counter-clockwise order seen from the free side
// (where a x + b y + c z + d > 0); empty when the plane misses the box.
std::vector<Vec3> planeInBox(const Plane& plane);

struct Arrow {
  Vec3 tail;         // m
  Vec3 head;         // m
  double strength;   // |F| / max |F| over the drawn nodes, in [0, 1]
  double magnitude;  // |F|, N
};
// At most `perAxis`^3 field nodes, evenly subsampled (6 per axis keeps the box readable); the
// longest arrow is `longest` metres. Nodes with zero force are left out.
std::vector<Arrow> fieldArrows(const ForceField& field, int perAxis = 6, double longest = 0.4);
// The colour of an arrow of relative strength s in [0, 1], RGB in [0, 1]: dark blue through
// green and yellow to red (the legend uses the same map).
std::array<float, 3> strengthColour(double s);

}  // namespace jello::viewer
