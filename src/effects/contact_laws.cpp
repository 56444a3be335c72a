// The contact laws other than the course's penalty, on every obstacle through its
// penetrations (src/effects/obstacle.h).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "src/effects/obstacle.h"

namespace jello {
namespace {

// block += scale * a b^T, block 3x3 row-major.
void addOuter(double* block, const Vec3& a, const Vec3& b, double scale) {
  const double u[3] = {a.x, a.y, a.z}, w[3] = {b.x, b.y, b.z};
  for (int r = 0; r < 3; ++r)
    for (int q = 0; q < 3; ++q) block[3 * r + q] += scale * u[r] * w[q];
}

void add(double* f, int n, int p, const Vec3& force) {
  f[p] += force.x;
  f[n + p] += force.y;
  f[2 * n + p] += force.z;
}

}  // namespace

ContactLawValue smoothContactLaw(double q, double k, double layer) {
  if (!(q > 0.0)) return {};
  if (q < layer) return {k * q * q * q / (6.0 * layer), k * q * q / (2.0 * layer), k * q / layer};
  const double s = q - 0.5 * layer;
  return {0.5 * k * s * s + k * layer * layer / 24.0, k * s, k};
}

ContactLawValue barrierContactLaw(double q, double kappa, double dhat) {
  const double d = -q;
  if (!(d < dhat)) return {};
  if (!(d > 0.0)) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    return {inf, inf, inf};
  }
  // b = -kappa g^2 L, g = d - dhat, L = ln(d/dhat);
  // b' = -kappa (2 g L + g^2/d),  b'' = -kappa (2 L + 4 g/d - g^2/d^2); e(q) = b(-q).
  const double g = d - dhat, L = std::log(d / dhat);
  return {-kappa * g * g * L, kappa * (2.0 * g * L + g * g / d),
          -kappa * (2.0 * L + 4.0 * g / d - g * g / (d * d))};
}

ContactLawValue Obstacle::law(double depth) const {
  if (k_.model == ContactModel::Barrier) return barrierContactLaw(depth, k_.kappa, k_.dhat);
  return smoothContactLaw(depth, k_.stiffness, k_.layer);
}

// The damping's weight: the smooth law's rises with its stiffness, w = e''/kc, 0 at the surface
// and 1 past the layer; the barrier has none.
double Obstacle::dampingWeight(const ContactLawValue& e) const {
  if (k_.model == ContactModel::Barrier) return 0.0;
  return k_.stiffness > 0.0 ? e.stiffness / k_.stiffness : 1.0;
}

double Obstacle::dampingWeightSlope(double depth) const {
  if (k_.model != ContactModel::Smooth || !(depth > 0.0) || !(depth < k_.layer)) return 0.0;
  return k_.stiffness > 0.0 ? 1.0 / k_.layer : 0.0;
}

double Obstacle::stepBound(const Vec3& x, const Vec3& dx) const {
  // Conservative advancement: the distance is 1-Lipschitz, so x + s dx cannot reach the surface
  // before s grows by d(x + s dx) / |dx|.
  const double length = norm(dx);
  if (!(length > 0.0)) return 1.0;
  double s = 0.0;
  for (int i = 0; i < 200; ++i) {
    const double d = signedDistance(x + dx * s);
    if (!(d > 1e-9)) return s;
    s += d / length;
    if (s >= 1.0) return 1.0;
  }
  return s;
}

bool Obstacle::addLawForces(const double* x, const double* v, double* f, int n, int lo,
                            int hi) const {
  const double r = reach();
  if (!mayTouch(x, n, lo, hi, r)) return false;
  Penetration touch[kMaxPenetrations];
  for (int p = lo; p < hi; ++p) {
    const int count = penetrations(pointAt(x, n, p), r, touch);
    for (int i = 0; i < count; ++i) {
      const Penetration& q = touch[i];
      const ContactLawValue e = law(q.depth);
      const Vec3 normal = unitVector(q.gradient * -1.0);
      const double w = dampingWeight(e);
      const double vn = dot(normal, pointAt(v, n, p));
      add(f, n, p, q.gradient * -e.force - normal * (k_.damping * w * vn));
    }
  }
  return true;
}

double Obstacle::lawEnergy(const double* x, int n) const {
  Penetration touch[kMaxPenetrations];
  const double r = reach();
  double energy = 0.0;
  for (int p = 0; p < n; ++p) {
    const int count = penetrations(pointAt(x, n, p), r, touch);
    for (int i = 0; i < count; ++i) energy += law(touch[i].depth).energy;
  }
  return energy;
}

void Obstacle::addLawJacobian(const double* x, int n, JacobianBlocks& out) const {
  Penetration touch[kMaxPenetrations];
  const double r = reach();
  for (int p = 0; p < n; ++p) {
    const int count = penetrations(pointAt(x, n, p), r, touch);
    double* K = out.diagK + 9 * static_cast<std::ptrdiff_t>(p);
    double* D = out.diagD + 9 * static_cast<std::ptrdiff_t>(p);
    for (int i = 0; i < count; ++i) {
      const Penetration& q = touch[i];
      const ContactLawValue e = law(q.depth);
      addOuter(K, q.gradient, q.gradient, -e.stiffness);
      if (!out.clampCompression) {
        for (int j = 0; j < 9; ++j) K[j] -= e.force * q.hessian[j];
      }
      const Vec3 normal = unitVector(q.gradient * -1.0);
      const double w = dampingWeight(e);
      addOuter(D, normal, normal, -k_.damping * w);
      // The weight grows with the depth, so the damping force -c w(q) vn n changes with x too:
      // by c vn w'(q) |g| n n^T. Left out, Newton cycled at an impact on jello.w (a point
      // moving at metres a second through the 5 mm layer: c |vn| w' of 150 N/m against
      // kc = 400). Moving out (vn > 0) the term is a negative stiffness: dropped under the clamp.
      if (out.velocities) {
        const double vn = dot(normal, pointAt(out.velocities, n, p));
        double s = k_.damping * vn * dampingWeightSlope(q.depth) * norm(q.gradient);
        if (out.clampCompression) s = std::min(s, 0.0);
        addOuter(K, normal, normal, s);
      }
    }
  }
}

}  // namespace jello
