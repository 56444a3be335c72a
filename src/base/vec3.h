// A 3-vector for geometry at the edges of the model (file I/O, presets, contact normals).
// Hot loops do not use it: they run over the component-major state arrays (see state.h).
#pragma once

#include <cmath>

namespace jello {

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  constexpr bool operator==(const Vec3&) const = default;
};

constexpr double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Point p of a 3n component-major array (x of every point, then y, then z).
inline Vec3 pointAt(const double* x, int n, int p) {
  return {x[p], x[n + p], x[2 * n + p]};
}

inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
// The largest component's magnitude: what to scale by before squaring.
inline double maxAbs(const Vec3& a) {
  return std::fmax(std::fabs(a.x), std::fmax(std::fabs(a.y), std::fabs(a.z)));
}
// a / |a|, scaled by its largest component first, so that neither |a|^2 overflows (components
// up to the largest double) nor underflows (down to the smallest subnormal). The zero vector
// and non-finite vectors give NaN components: callers refuse those first.
inline Vec3 unitVector(const Vec3& a) {
  const double s = maxAbs(a);
  const Vec3 b{a.x / s, a.y / s, a.z / s};  // divided: 1/s overflows for subnormal s
  const double l = norm(b);
  return {b.x / l, b.y / l, b.z / l};
}

}  // namespace jello
