// The extra-credit obstacles beyond the plane and the sphere: a solid cone and a spiral ramp,
// with the same penalty contact (src/PHYSICS.md). Each is described by its penetration depth
// phi(x) > 0 inside the solid, its gradient and Hessian; then for a point inside
//   energy = 1/2 kc phi^2,   f = -kc phi grad(phi) - dc (n.v) n,   n = -grad(phi)/|grad(phi)|,
//   K = -kc (grad(phi) grad(phi)^T + phi Hess(phi)),   D = -dc n n^T,
// the Hessian term (the surface's curvature) dropped under the clamp, as the sphere's is.
//   cone:   phi = the depth below the nearer of the lateral surface and the base disk (exact
//           distances, |grad(phi)| = 1);
//   spiral: phi = the least of the vertical depth below the helicoid top, the height above the
//           slab's bottom, the distances to the outer and inner cylinders, and the arc lengths
//           to the ramp's two ends (so phi falls to 0 on every face: no energy jumps).
#pragma once

#include <optional>

#include "src/effects/contact.h"
#include "src/effects/jacobian_blocks.h"
#include "src/world/world.h"

namespace jello {

// The penetration of point x into a cone or a spiral ramp, or nothing when x is outside.
std::optional<Penetration> conePenetration(const Cone& cone, const Vec3& x);
std::optional<Penetration> spiralPenetration(const Spiral& spiral, const Vec3& x);
// For x outside the cone: its exact distance D to the solid, as a penetration of depth -D (the
// depth's gradient and Hessian those of -D). In the meridian half-plane (h along the axis from
// the apex, r from it) the solid is the triangle (0,0), (H,R), (H,0), and D the distance to its
// lateral edge or its base edge.
Penetration coneExterior(const Cone& cone, const Vec3& x);
// For x outside the spiral ramp: a lower bound D on its distance to the solid, as a penetration
// of depth -D: per turn the largest of its faces' distances (each a lower bound on the distance
// to that turn's slab: exact for the cylinders and the end planes, the vertical gap over
// sqrt(1 + G^2) for the top and bottom, G = (pi/2) c / (rInner/2) bounding the helicoid's slope
// along any chord, c = pitch / 2 pi), over the turns the least. It is 0 on the surface and the
// distance itself off a face's middle (to that factor), 1/sqrt(2) of it off an edge; the barrier
// holds the ramp with it, and, a lower bound, conservative advancement on it never steps a point
// in.
Penetration spiralExterior(const Spiral& spiral, const Vec3& x);

// Penalty contact with one of them (src/effects/obstacle.h has what each method answers); all
// arrays component-major, n points.
class ObstacleContact final : public Obstacle {
 public:
  ObstacleContact(const Cone& cone, ContactConstants k);
  ObstacleContact(const Spiral& spiral, ContactConstants k);
  ObstacleKind kind() const override { return cone_ ? ObstacleKind::Cone : ObstacleKind::Spiral; }
  std::optional<Penetration> penetration(const Vec3& x) const;
  bool inside(const Vec3& x) const { return penetration(x).has_value(); }
  bool addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                        int hi) const override;
  double penaltyEnergy(const double* x, int n) const override;
  void addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const override;
  int penetrations(const Vec3& x, double reach, Penetration* out) const override;
  double signedDistance(const Vec3& x) const override;
  // CVODE's roots: the cone's signed distance (continuous, 0 on its surface); the spiral's
  // face depths, max over its turns of their min, negated (obstacles.cpp, spiralRoot).
  int rootsPerPoint() const override { return 1; }
  void roots(const double* x, int n, double* g) const override;
  double depth(const Vec3& x) const override;
  bool contactBegins(const double* x0, const double* x1, int n) const override;
  int contactSprings(const Vec3& x) const override;
  void addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                         double weight, const std::array<double*, 3>& w) const override;

 private:
  std::optional<Cone> cone_;
  std::optional<Spiral> spiral_;
};

}  // namespace jello
