#include "viewer/surface.h"

#include <algorithm>

namespace jello::viewer {

bool onSurface(const Lattice& lattice, int index) {
  const int n = lattice.n, i = index / (n * n), j = (index / n) % n, k = index % n;
  const auto edge = [n](int a) { return a == 0 || a == n - 1; };
  return edge(i) || edge(j) || edge(k);
}

SurfaceMesh surfaceMesh(const Lattice& lattice) {
  SurfaceMesh mesh;
  const int n = lattice.n;
  mesh.n = n;
  for (int p = 0; p < lattice.numPoints(); ++p) {
    if (onSurface(lattice, p)) mesh.points.push_back(p);
  }
  // Each of the six faces: fix one axis at 0 or n-1, walk the other two.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {0, n - 1}) {
      const auto at = [&](int a, int b) {
        int ijk[3];
        ijk[axis] = side;
        ijk[(axis + 1) % 3] = a;
        ijk[(axis + 2) % 3] = b;
        return lattice.index(ijk[0], ijk[1], ijk[2]);
      };
      // (axis+1, axis+2) is a right-handed pair with `axis`, so counter-clockwise in (a, b)
      // faces +axis: keep it on the far side, reverse it on the near one.
      const bool outwardPositive = side == n - 1;
      for (int a = 0; a + 1 < n; ++a) {
        for (int b = 0; b + 1 < n; ++b) {
          const int p00 = at(a, b), p10 = at(a + 1, b), p11 = at(a + 1, b + 1), p01 = at(a, b + 1);
          const auto uv = [n](int i) { return static_cast<float>(i) / static_cast<float>(n - 1); };
          const std::array<float, 2> t00{uv(a), uv(b)}, t10{uv(a + 1), uv(b)},
              t11{uv(a + 1), uv(b + 1)}, t01{uv(a), uv(b + 1)};
          if (outwardPositive) {
            mesh.triangles.push_back({p00, p10, p11});
            mesh.triangles.push_back({p00, p11, p01});
            mesh.uv.push_back({t00, t10, t11});
            mesh.uv.push_back({t00, t11, t01});
          } else {
            mesh.triangles.push_back({p00, p11, p10});
            mesh.triangles.push_back({p00, p01, p11});
            mesh.uv.push_back({t00, t11, t10});
            mesh.uv.push_back({t00, t01, t11});
          }
        }
      }
    }
  }
  return mesh;
}

std::vector<Vec3> vertexNormals(const SurfaceMesh& mesh, const State& state) {
  std::vector<Vec3> normals(static_cast<std::size_t>(state.numPoints()));
  for (const auto& t : mesh.triangles) {
    const Vec3 a = state.position(t[0]), b = state.position(t[1]), c = state.position(t[2]);
    // The cross product's length weights each triangle by its area.
    const Vec3 face = cross(b - a, c - a);
    for (int p : t) normals[p] += face;
  }
  for (Vec3& v : normals) {
    const double length = norm(v);
    v = length > 1e-300 ? v * (1.0 / length) : Vec3{};
  }
  return normals;
}

std::vector<Spring> surfaceSprings(const std::vector<Spring>& springs, const Lattice& lattice) {
  std::vector<Spring> out;
  std::copy_if(springs.begin(), springs.end(), std::back_inserter(out),
               [&](const Spring& s) { return onSurface(lattice, s.a) && onSurface(lattice, s.b); });
  return out;
}

}  // namespace jello::viewer
