#include "src/effects/contact.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace jello {
namespace {

// block += scale * u u^T, block 3x3 row-major.
void addOuter(double* block, const Vec3& u, double scale) {
  const double c[3] = {u.x, u.y, u.z};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) block[3 * r + q] += scale * c[r] * c[q];
}

double* blockOf(double* diag, int p) {
  return diag + 9 * static_cast<std::ptrdiff_t>(p);
}

}  // namespace

std::string_view obstacleName(ObstacleKind kind) {
  switch (kind) {
#define JELLO_OBSTACLE_NAME(kind, name) \
  case ObstacleKind::kind:              \
    return name;
    JELLO_OBSTACLES(JELLO_OBSTACLE_NAME)
#undef JELLO_OBSTACLE_NAME
  }
  return "?";
}

// The loops below are branch-free (selects, an OR reduction) so that they vectorize: they run
// in every force evaluation.

bool WallContact::allInside(const double* __restrict x, int n, int lo, int hi) {
  int outside = 0;
  for (int e = 0; e < 3; ++e)
    for (int i = e * n + lo; i < e * n + hi; ++i) outside |= std::abs(x[i]) > kBoxHalfSize;
  return outside == 0;
}

bool WallContact::addPenaltyForces(const double* __restrict x, const double* __restrict v,
                                   double* __restrict f, int n, int lo, int hi) const {
  if (allInside(x, n, lo, hi)) return false;
  const double k = constants().stiffness, c = constants().damping;
  for (int e = 0; e < 3; ++e)
    for (int i = e * n + lo; i < e * n + hi; ++i) {
      const double over = x[i] - kBoxHalfSize, under = x[i] + kBoxHalfSize;
      const double depth = over > 0.0 ? over : under < 0.0 ? under : 0.0;
      f[i] -= depth != 0.0 ? k * depth + c * v[i] : 0.0;
    }
  return true;
}

double WallContact::penaltyEnergy(const double* x, int n) const {
  double e = 0.0;
  for (int i = 0; i < 3 * n; ++i) {
    const double depth = std::max(0.0, std::abs(x[i]) - kBoxHalfSize);
    e += depth * depth;
  }
  return 0.5 * constants().stiffness * e;
}

void WallContact::addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const {
  for (int axis = 0; axis < 3; ++axis)
    for (int p = 0; p < n; ++p) {
      if (std::abs(x[axis * n + p]) <= kBoxHalfSize) continue;
      blockOf(out.diagK, p)[4 * axis] -= constants().stiffness;  // entry (axis, axis)
      blockOf(out.diagD, p)[4 * axis] -= constants().damping;
    }
}

bool WallContact::mayTouch(const double* x, int n, int lo, int hi, double reach) const {
  if (reach == 0.0) return !allInside(x, n, lo, hi);
  const double inner = kBoxHalfSize - reach;
  for (int e = 0; e < 3; ++e)
    for (int i = e * n + lo; i < e * n + hi; ++i) {
      if (!(std::abs(x[i]) < inner)) return true;
    }
  return false;
}

int WallContact::penetrations(const Vec3& x, double reach, Penetration* out) const {
  const double c[3] = {x.x, x.y, x.z};
  int count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double over = std::abs(c[axis]) - kBoxHalfSize;
    if (!(over > -reach)) continue;
    Penetration& q = out[count++];
    q = Penetration{};
    q.depth = over;
    const double sign = c[axis] > 0.0 ? 1.0 : -1.0;
    q.gradient = Vec3{axis == 0 ? sign : 0.0, axis == 1 ? sign : 0.0, axis == 2 ? sign : 0.0};
  }
  return count;
}

double WallContact::signedDistance(const Vec3& x) const {
  return kBoxHalfSize - std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)});
}

double WallContact::stepBound(const Vec3& x, const Vec3& dx) const {
  const double c[3] = {x.x, x.y, x.z}, d[3] = {dx.x, dx.y, dx.z};
  double bound = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    if (d[axis] == 0.0) continue;
    // The wall it moves towards, at +-2: reached at s = (2 - sign x) / |dx|.
    const double gap = kBoxHalfSize - (d[axis] > 0.0 ? c[axis] : -c[axis]);
    bound = std::min(bound, std::max(0.0, gap) / std::abs(d[axis]));
  }
  return bound;
}

double WallContact::depth(const Vec3& x) const {
  return std::max({0.0, std::abs(x.x) - kBoxHalfSize, std::abs(x.y) - kBoxHalfSize,
                   std::abs(x.z) - kBoxHalfSize});
}

bool WallContact::contactBegins(const double* x0, const double* x1, int n) const {
  for (int i = 0; i < 3 * n; ++i) {
    if (std::abs(x1[i]) > kBoxHalfSize && std::abs(x0[i]) <= kBoxHalfSize) return true;
  }
  return false;
}

int WallContact::contactSprings(const Vec3& x) const {
  return int(std::abs(x.x) > kBoxHalfSize) + int(std::abs(x.y) > kBoxHalfSize) +
         int(std::abs(x.z) > kBoxHalfSize);
}

void WallContact::addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                                    double weight, const std::array<double*, 3>& w) const {
  for (int c = 0; c < 3; ++c) {
    const double* __restrict xc = x + c * static_cast<std::ptrdiff_t>(n);
    double* __restrict wc = w[c];
#pragma omp simd
    for (std::ptrdiff_t p = lo; p < hi; ++p) wc[p] += std::abs(xc[p]) > kBoxHalfSize ? weight : 0.0;
  }
}

void WallContact::roots(const double* x, int n, double* g) const {
  for (int i = 0; i < 3 * n; ++i) g[i] = kBoxHalfSize - std::abs(x[i]);
}

PlaneContact::PlaneContact(const Plane& plane, ContactConstants k) : Obstacle(k) {
  // Scaled by the largest coefficient first: normals from 1e-300 to 1e300 give the same plane.
  const Vec3 n{plane.a, plane.b, plane.c};
  const double scale = maxAbs(n);
  const Vec3 scaled{n.x / scale, n.y / scale, n.z / scale};  // 1/scale overflows if subnormal
  const double len = norm(scaled);
  normal_ = scaled * (1.0 / len);
  offset_ = (plane.d / scale) / len;
}

bool PlaneContact::addPenaltyForces(const double* __restrict x, const double* __restrict v,
                                    double* __restrict f, int n, int lo, int hi) const {
  const double ux = normal_.x, uy = normal_.y, uz = normal_.z;
  const double k = constants().stiffness, c = constants().damping;
  for (int p = lo; p < hi; ++p) {
    const double dist = ux * x[p] + uy * x[n + p] + uz * x[2 * n + p] + offset_;
    const double vn = ux * v[p] + uy * v[n + p] + uz * v[2 * n + p];
    const double s = dist < 0.0 ? -k * dist - c * vn : 0.0;
    f[p] += s * ux;
    f[n + p] += s * uy;
    f[2 * n + p] += s * uz;
  }
  return true;
}

double PlaneContact::penaltyEnergy(const double* x, int n) const {
  double e = 0.0;
  for (int p = 0; p < n; ++p) {
    const double dist =
        normal_.x * x[p] + normal_.y * x[n + p] + normal_.z * x[2 * n + p] + offset_;
    if (dist < 0.0) e += dist * dist;
  }
  return 0.5 * constants().stiffness * e;
}

void PlaneContact::addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const {
  for (int p = 0; p < n; ++p) {
    const Vec3 xp{x[p], x[n + p], x[2 * n + p]};
    if (dot(normal_, xp) + offset_ >= 0.0) continue;
    addOuter(blockOf(out.diagK, p), normal_, -constants().stiffness);
    addOuter(blockOf(out.diagD, p), normal_, -constants().damping);
  }
}

int PlaneContact::penetrations(const Vec3& x, double reach, Penetration* out) const {
  const double s = side(x);
  if (!(s < reach)) return 0;
  out[0] = Penetration{};
  out[0].depth = -s;
  out[0].gradient = normal_ * -1.0;
  return 1;
}

double PlaneContact::stepBound(const Vec3& x, const Vec3& dx) const {
  const double approach = -dot(normal_, dx);  // how fast the side falls along dx
  if (!(approach > 0.0)) return 1.0;
  return std::min(1.0, std::max(0.0, side(x)) / approach);
}

double PlaneContact::depth(const Vec3& x) const {
  return std::max(0.0, -side(x));
}

bool PlaneContact::contactBegins(const double* x0, const double* x1, int n) const {
  for (int p = 0; p < n; ++p) {
    if (side(pointAt(x1, n, p)) < 0.0 && side(pointAt(x0, n, p)) >= 0.0) return true;
  }
  return false;
}

int PlaneContact::contactSprings(const Vec3& x) const {
  return side(x) < 0.0 ? 1 : 0;
}

void PlaneContact::addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                                     double weight, const std::array<double*, 3>& w) const {
  addToAllCoordinates(lo, hi, weight, w,
                      [&](std::ptrdiff_t p) { return side(pointAt(x, n, int(p))) < 0.0; });
}

void PlaneContact::roots(const double* x, int n, double* g) const {
  const Vec3 u = normal_;
  for (int p = 0; p < n; ++p) g[p] = u.x * x[p] + u.y * x[n + p] + u.z * x[2 * n + p] + offset_;
}

bool SphereContact::addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                                     int hi) const {
  const Vec3 c = sphere_.center;
  const double r = sphere_.radius;
  for (int p = lo; p < hi; ++p) {
    const Vec3 d{x[p] - c.x, x[n + p] - c.y, x[2 * n + p] - c.z};
    const double l2 = dot(d, d);
    if (l2 >= r * r) continue;
    const double l = std::sqrt(l2);
    const Vec3 u = l > 0.0 ? d * (1.0 / l) : Vec3{0.0, 0.0, 1.0};  // centre: push up
    const double vn = u.x * v[p] + u.y * v[n + p] + u.z * v[2 * n + p];
    const double s = constants().stiffness * (r - l) - constants().damping * vn;
    f[p] += s * u.x;
    f[n + p] += s * u.y;
    f[2 * n + p] += s * u.z;
  }
  return true;
}

double SphereContact::penaltyEnergy(const double* x, int n) const {
  double e = 0.0;
  for (int p = 0; p < n; ++p) {
    const Vec3 d{x[p] - sphere_.center.x, x[n + p] - sphere_.center.y,
                 x[2 * n + p] - sphere_.center.z};
    const double depth = sphere_.radius - norm(d);
    if (depth > 0.0) e += depth * depth;
  }
  return 0.5 * constants().stiffness * e;
}

void SphereContact::addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const {
  const double R = sphere_.radius;
  for (int p = 0; p < n; ++p) {
    const Vec3 r = Vec3{x[p], x[n + p], x[2 * n + p]} - sphere_.center;
    const double l = norm(r);
    if (!(l < R && l > 0.0)) continue;
    const Vec3 u = r * (1.0 / l);
    // The curvature term kc (R/l - 1)(I - n n^T): positive, dropped by the clamp.
    const double t = out.clampCompression ? 0.0 : constants().stiffness * (R / l - 1.0);
    double* K = blockOf(out.diagK, p);
    addOuter(K, u, -constants().stiffness - t);
    for (int e = 0; e < 3; ++e) K[4 * e] += t;
    addOuter(blockOf(out.diagD, p), u, -constants().damping);
  }
}

int SphereContact::penetrations(const Vec3& x, double reach, Penetration* out) const {
  const Vec3 r = x - sphere_.center;
  const double l = norm(r);
  if (!(l < sphere_.radius + reach)) return 0;
  Penetration& q = out[0];
  q = Penetration{};
  q.depth = sphere_.radius - l;
  if (l > 0.0) {
    const Vec3 u = r * (1.0 / l);
    q.gradient = u * -1.0;
    for (int e = 0; e < 3; ++e) q.hessian[4 * e] -= 1.0 / l;
    addOuter(q.hessian, u, 1.0 / l);
  } else {
    q.gradient = Vec3{0.0, 0.0, -1.0};  // the centre: pushed up, as the penalty does
  }
  return 1;
}

double SphereContact::stepBound(const Vec3& x, const Vec3& dx) const {
  // |r + s dx|^2 = R^2: a s^2 + b s + c = 0 with c > 0 outside; the first root, if it comes.
  const Vec3 r = x - sphere_.center;
  const double a = dot(dx, dx), b = 2.0 * dot(r, dx);
  const double c = dot(r, r) - sphere_.radius * sphere_.radius;
  if (!(a > 0.0) || !(b < 0.0)) return 1.0;
  if (!(c > 0.0)) return 0.0;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return 1.0;
  // The smaller root, written to keep its digits: 2c / (-b + sqrt(disc)).
  return std::min(1.0, 2.0 * c / (-b + std::sqrt(disc)));
}

double SphereContact::depth(const Vec3& x) const {
  return std::max(0.0, sphere_.radius - norm(x - sphere_.center));
}

bool SphereContact::contactBegins(const double* x0, const double* x1, int n) const {
  for (int p = 0; p < n; ++p) {
    if (inside(pointAt(x1, n, p)) && !inside(pointAt(x0, n, p))) return true;
  }
  return false;
}

int SphereContact::contactSprings(const Vec3& x) const {
  return inside(x) ? 1 : 0;
}

void SphereContact::addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                                      double weight, const std::array<double*, 3>& w) const {
  addToAllCoordinates(lo, hi, weight, w,
                      [&](std::ptrdiff_t p) { return inside(pointAt(x, n, int(p))); });
}

void SphereContact::roots(const double* x, int n, double* g) const {
  for (int p = 0; p < n; ++p) g[p] = norm(pointAt(x, n, p) - sphere_.center) - sphere_.radius;
}

}  // namespace jello
