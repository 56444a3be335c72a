#include "contact.h"

#include <algorithm>
#include <cmath>

namespace jello {

bool WallContact::allInside(const double* x, int n) {
  double lo = 0.0, hi = 0.0;
  for (int i = 0; i < 3 * n; ++i) {
    lo = std::min(lo, x[i]);
    hi = std::max(hi, x[i]);
  }
  return lo >= -kBoxHalfSize && hi <= kBoxHalfSize;
}

void WallContact::accumulate(const double* x, const double* v, double* f, int n) const {
  // Each component is its own pair of walls: n = -/+ e_c, so the spring acts on that
  // component alone.
  for (int i = 0; i < 3 * n; ++i) {
    const double depth = x[i] > kBoxHalfSize    ? x[i] - kBoxHalfSize
                         : x[i] < -kBoxHalfSize ? x[i] + kBoxHalfSize
                                                : 0.0;
    if (depth != 0.0) f[i] -= k_.stiffness * depth + k_.damping * v[i];
  }
}

double WallContact::energy(const double* x, int n) const {
  double e = 0.0;
  for (int i = 0; i < 3 * n; ++i) {
    const double depth = std::max(0.0, std::abs(x[i]) - kBoxHalfSize);
    e += depth * depth;
  }
  return 0.5 * k_.stiffness * e;
}

PlaneContact::PlaneContact(const Plane& plane, ContactConstants k) : k_(k) {
  const double len = norm(Vec3{plane.a, plane.b, plane.c});
  normal_ = Vec3{plane.a, plane.b, plane.c} * (1.0 / len);
  offset_ = plane.d / len;
}

void PlaneContact::accumulate(const double* x, const double* v, double* f, int n) const {
  const Vec3 u = normal_;
  for (int p = 0; p < n; ++p) {
    const double dist = u.x * x[p] + u.y * x[n + p] + u.z * x[2 * n + p] + offset_;
    if (dist >= 0.0) continue;
    const double vn = u.x * v[p] + u.y * v[n + p] + u.z * v[2 * n + p];
    const double s = -k_.stiffness * dist - k_.damping * vn;
    f[p] += s * u.x;
    f[n + p] += s * u.y;
    f[2 * n + p] += s * u.z;
  }
}

double PlaneContact::energy(const double* x, int n) const {
  double e = 0.0;
  for (int p = 0; p < n; ++p) {
    const double dist =
        normal_.x * x[p] + normal_.y * x[n + p] + normal_.z * x[2 * n + p] + offset_;
    if (dist < 0.0) e += dist * dist;
  }
  return 0.5 * k_.stiffness * e;
}

void SphereContact::accumulate(const double* x, const double* v, double* f, int n) const {
  const Vec3 c = sphere_.center;
  const double r = sphere_.radius;
  for (int p = 0; p < n; ++p) {
    const Vec3 d{x[p] - c.x, x[n + p] - c.y, x[2 * n + p] - c.z};
    const double l2 = dot(d, d);
    if (l2 >= r * r) continue;
    const double l = std::sqrt(l2);
    const Vec3 u = l > 0.0 ? d * (1.0 / l) : Vec3{0.0, 0.0, 1.0};  // centre: push up
    const double vn = u.x * v[p] + u.y * v[n + p] + u.z * v[2 * n + p];
    const double s = k_.stiffness * (r - l) - k_.damping * vn;
    f[p] += s * u.x;
    f[n + p] += s * u.y;
    f[2 * n + p] += s * u.z;
  }
}

double SphereContact::energy(const double* x, int n) const {
  double e = 0.0;
  for (int p = 0; p < n; ++p) {
    const Vec3 d{x[p] - sphere_.center.x, x[n + p] - sphere_.center.y,
                 x[2 * n + p] - sphere_.center.z};
    const double depth = sphere_.radius - norm(d);
    if (depth > 0.0) e += depth * depth;
  }
  return 0.5 * k_.stiffness * e;
}

}  // namespace jello
