#include "viewer/box_geometry.h"

#include <algorithm>
#include <cmath>

#include "src/effects/contact.h"

namespace jello::viewer {

std::vector<Vec3> floorCorners() {
  const double h = kBoxHalfSize;
  return {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}};
}

std::array<std::pair<Vec3, Vec3>, 12> boxEdges() {
  const double h = kBoxHalfSize;
  std::array<std::pair<Vec3, Vec3>, 12> edges;
  std::size_t e = 0;
  // Edges along each axis: the other two coordinates at +-h.
  for (int axis = 0; axis < 3; ++axis) {
    for (double u : {-h, h}) {
      for (double w : {-h, h}) {
        double lo[3], hi[3];
        lo[axis] = -h;
        hi[axis] = h;
        lo[(axis + 1) % 3] = hi[(axis + 1) % 3] = u;
        lo[(axis + 2) % 3] = hi[(axis + 2) % 3] = w;
        edges[e++] = {Vec3{lo[0], lo[1], lo[2]}, Vec3{hi[0], hi[1], hi[2]}};
      }
    }
  }
  return edges;
}

std::vector<Vec3> planeInBox(const Plane& plane) {
  // Scaled by the largest coefficient, so that huge or tiny coefficients neither overflow nor
  // underflow in the products.
  const double scale = maxAbs(Vec3{plane.a, plane.b, plane.c});
  const Vec3 normal{plane.a / scale, plane.b / scale, plane.c / scale};
  const double offset = plane.d / scale;
  const auto side = [&](const Vec3& p) { return dot(normal, p) + offset; };
  std::vector<Vec3> corners;
  for (const auto& [a, b] : boxEdges()) {
    const double sa = side(a), sb = side(b);
    if ((sa < 0.0) == (sb < 0.0) && sa != 0.0) continue;
    const double t = sa == sb ? 0.0 : sa / (sa - sb);
    corners.push_back(a + (b - a) * t);
  }
  // Corners met at a box vertex appear up to three times.
  std::vector<Vec3> unique;
  for (const Vec3& c : corners) {
    if (std::none_of(unique.begin(), unique.end(),
                     [&](const Vec3& u) { return norm(u - c) < 1e-9; })) {
      unique.push_back(c);
    }
  }
  if (unique.size() < 3) return {};
  Vec3 centre;
  for (const Vec3& c : unique) centre += c * (1.0 / double(unique.size()));
  // An orthonormal pair in the plane, (e1, e2, normal) right-handed.
  const Vec3 n = normal * (1.0 / norm(normal));
  const Vec3 helper = std::abs(n.x) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  Vec3 e1 = cross(helper, n);
  e1 = e1 * (1.0 / norm(e1));
  const Vec3 e2 = cross(n, e1);
  const auto angle = [&](const Vec3& p) {
    return std::atan2(dot(p - centre, e2), dot(p - centre, e1));
  };
  std::sort(unique.begin(), unique.end(),
            [&](const Vec3& p, const Vec3& q) { return angle(p) < angle(q); });
  return unique;
}

std::array<float, 3> strengthColour(double s) {
  // Piecewise linear through four stops.
  static constexpr float stops[4][3] = {
      {0.15f, 0.25f, 0.85f}, {0.1f, 0.8f, 0.4f}, {0.95f, 0.9f, 0.15f}, {0.95f, 0.2f, 0.15f}};
  const double x = std::clamp(s, 0.0, 1.0) * 3.0;
  const int i = std::min(2, static_cast<int>(x));
  const float u = static_cast<float>(x - i);
  std::array<float, 3> c{};
  for (int k = 0; k < 3; ++k) c[k] = stops[i][k] * (1.0f - u) + stops[i + 1][k] * u;
  return c;
}

std::vector<Arrow> fieldArrows(const ForceField& field, int perAxis, double longest) {
  std::vector<Arrow> arrows;
  const int r = field.resolution;
  if (r < 2) return arrows;
  const int count = std::min(perAxis, r);
  std::vector<int> nodes;
  for (int i = 0; i < count; ++i) {
    nodes.push_back(count == 1 ? 0 : int(std::lround(double(i) * (r - 1) / (count - 1))));
  }
  double strongest = 0.0;
  for (int i : nodes) {
    for (int j : nodes) {
      for (int k : nodes) strongest = std::max(strongest, norm(field.forces[(i * r + j) * r + k]));
    }
  }
  if (!(strongest > 0.0) || !std::isfinite(strongest)) return arrows;
  const double spacing = 2.0 * kBoxHalfSize / (r - 1);
  for (int i : nodes) {
    for (int j : nodes) {
      for (int k : nodes) {
        const Vec3 f = field.forces[(i * r + j) * r + k];
        const double magnitude = norm(f);
        if (magnitude == 0.0) continue;
        const Vec3 tail{-kBoxHalfSize + i * spacing, -kBoxHalfSize + j * spacing,
                        -kBoxHalfSize + k * spacing};
        arrows.push_back(
            {tail, tail + f * (longest / strongest), magnitude / strongest, magnitude});
      }
    }
  }
  return arrows;
}

}  // namespace jello::viewer
