// Coulomb friction on every obstacle (src/PHYSICS.md, "Friction"): IPC's smoothed friction in
// the velocity form, on each contact a solid's penetrations give, with the normal force of the
// state it is evaluated at and no derivative of it or of the normal in the Jacobian (lagged).
#include <cstddef>

#include "src/effects/obstacle.h"

namespace jello {
namespace {

void add(double* f, int n, int p, const Vec3& force) {
  f[p] += force.x;
  f[n + p] += force.y;
  f[2 * n + p] += force.z;
}

}  // namespace

FrictionValue smoothedFriction(double slip, double slipSpeed) {
  const double e = slipSpeed;
  if (!(slip > 0.0)) return {0.0, 2.0 / e, -1.0 / (e * e)};
  if (slip < e)
    return {2.0 * slip / e - slip * slip / (e * e), 2.0 / e - slip / (e * e), -1.0 / (e * e)};
  return {1.0, 1.0 / slip, -1.0 / (slip * slip)};
}

double Obstacle::normalForce(double depth) const {
  if (k_.model == ContactModel::Penalty) return depth > 0.0 ? k_.stiffness * depth : 0.0;
  return law(depth).force;
}

int Obstacle::frictionContacts(const double* x, const double* v, int n, int p,
                               FrictionContact* out) const {
  Penetration touch[kMaxPenetrations];
  const int count = penetrations(pointAt(x, n, p), reach(), touch);
  int contacts = 0;
  for (int i = 0; i < count; ++i) {
    const double lambda = normalForce(touch[i].depth);
    if (!(lambda > 0.0)) continue;
    const Vec3 normal = unitVector(touch[i].gradient * -1.0);
    const Vec3 vp = pointAt(v, n, p);
    out[contacts++] = {k_.mu * lambda, normal, vp - normal * dot(normal, vp)};
  }
  return contacts;
}

void Obstacle::addFrictionForces(const double* x, const double* v, double* f, int n, int lo,
                                 int hi) const {
  if (!(k_.mu > 0.0)) return;
  FrictionContact c[kMaxPenetrations];
  for (int p = lo; p < hi; ++p) {
    const int count = frictionContacts(x, v, n, p, c);
    for (int i = 0; i < count; ++i) {
      const FrictionValue g = smoothedFriction(norm(c[i].slip), k_.slipSpeed);
      add(f, n, p, c[i].slip * (-c[i].bound * g.g));
    }
  }
}

double Obstacle::frictionPotential(const double* x, const double* v, int n) const {
  if (!(k_.mu > 0.0)) return 0.0;
  FrictionContact c[kMaxPenetrations];
  const double e = k_.slipSpeed;
  double potential = 0.0;
  for (int p = 0; p < n; ++p) {
    const int count = frictionContacts(x, v, n, p, c);
    for (int i = 0; i < count; ++i) {
      const double s = norm(c[i].slip);  // F0' = f1: s^2/e - s^3/(3 e^2), then s - e/3
      potential += c[i].bound * (s < e ? s * s / e - s * s * s / (3.0 * e * e) : s - e / 3.0);
    }
  }
  return potential;
}

double Obstacle::frictionPower(const double* x, const double* v, int n) const {
  if (!(k_.mu > 0.0)) return 0.0;
  FrictionContact c[kMaxPenetrations];
  double power = 0.0;
  for (int p = 0; p < n; ++p) {
    const int count = frictionContacts(x, v, n, p, c);
    for (int i = 0; i < count; ++i) {
      const double s = norm(c[i].slip);
      power -= c[i].bound * smoothedFriction(s, k_.slipSpeed).f1 * s;
    }
  }
  return power;
}

void Obstacle::addFrictionJacobian(const double* x, const double* v, int n,
                                   JacobianBlocks& out) const {
  if (!(k_.mu > 0.0)) return;
  FrictionContact c[kMaxPenetrations];
  for (int p = 0; p < n; ++p) {
    const int count = frictionContacts(x, v, n, p, c);
    double* D =
        (out.diagFriction ? out.diagFriction : out.diagD) + 9 * static_cast<std::ptrdiff_t>(p);
    for (int i = 0; i < count; ++i) {
      // D = -mu lambda (g T + g' u u^T / s), T = I - n n^T: symmetric, negative semidefinite
      // (along u it is -mu lambda f1'(s) <= 0, across it -mu lambda g).
      const Vec3& nrm = c[i].normal;
      const Vec3& u = c[i].slip;
      const double s = norm(u);
      const FrictionValue g = smoothedFriction(s, k_.slipSpeed);
      const double a[3] = {nrm.x, nrm.y, nrm.z}, w[3] = {u.x, u.y, u.z};
      const double across = -c[i].bound * g.g;
      const double along = s > 0.0 ? -c[i].bound * g.dg / s : 0.0;
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) {
          D[3 * r + q] += across * ((r == q ? 1.0 : 0.0) - a[r] * a[q]) + along * w[r] * w[q];
        }
    }
  }
}

}  // namespace jello
