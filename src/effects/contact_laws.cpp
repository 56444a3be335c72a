// The contact laws other than the course's penalty, on every obstacle through its
// penetrations (src/effects/obstacle.h).
#include <cstddef>

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

ContactLawValue Obstacle::law(double depth) const {
  return smoothContactLaw(depth, k_.stiffness, k_.layer);
}

bool Obstacle::addLawForces(const double* x, const double* v, double* f, int n, int lo,
                            int hi) const {
  if (!mayTouch(x, n, lo, hi)) return false;
  Penetration touch[kMaxPenetrations];
  for (int p = lo; p < hi; ++p) {
    const int count = penetrations(pointAt(x, n, p), touch);
    for (int i = 0; i < count; ++i) {
      const Penetration& q = touch[i];
      const ContactLawValue e = law(q.depth);
      const Vec3 normal = unitVector(q.gradient * -1.0);
      // The damping rises with the stiffness: w = e''/kc, 0 at the surface, 1 past the layer.
      const double w = k_.stiffness > 0.0 ? e.stiffness / k_.stiffness : 1.0;
      const double vn = dot(normal, pointAt(v, n, p));
      add(f, n, p, q.gradient * -e.force - normal * (k_.damping * w * vn));
    }
  }
  return true;
}

double Obstacle::lawEnergy(const double* x, int n) const {
  Penetration touch[kMaxPenetrations];
  double energy = 0.0;
  for (int p = 0; p < n; ++p) {
    const int count = penetrations(pointAt(x, n, p), touch);
    for (int i = 0; i < count; ++i) energy += law(touch[i].depth).energy;
  }
  return energy;
}

void Obstacle::addLawJacobian(const double* x, int n, JacobianBlocks& out) const {
  Penetration touch[kMaxPenetrations];
  for (int p = 0; p < n; ++p) {
    const int count = penetrations(pointAt(x, n, p), touch);
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
      const double w = k_.stiffness > 0.0 ? e.stiffness / k_.stiffness : 1.0;
      addOuter(D, normal, normal, -k_.damping * w);
    }
  }
}

}  // namespace jello
