// Penalty contact with the walls, the plane and the sphere (src/PHYSICS.md): a point on the
// solid side of a surface gets a rest-length-0 spring to its projection p on the surface,
//   f = -kc (n.(x - p)) n - dc (n.v) n,   energy = 1/2 kc (n.(x - p))^2,
// with n the unit normal pointing into free space. Walls: the six faces of the box [-2,2]^3,
// one spring per violated wall.
#pragma once

#include "src/effects/jacobian_blocks.h"
#include "src/effects/obstacle.h"
#include "src/world/world.h"

namespace jello {

inline constexpr double kBoxHalfSize = 2.0;  // m: the box is [-2,2]^3

// All arrays component-major, n points (src/effects/obstacle.h has what each method answers).
class WallContact final : public Obstacle {
 public:
  explicit WallContact(ContactConstants k) : Obstacle(k) {}
  ObstacleKind kind() const override { return ObstacleKind::Walls; }
  // True when every point (of [lo, hi)) is inside the box, so there is nothing to do.
  static bool allInside(const double* x, int n) { return allInside(x, n, 0, n); }
  static bool allInside(const double* x, int n, int lo, int hi);
  // Each component is its own pair of walls: normal -/+ e_c, so the spring acts on it alone.
  bool addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                        int hi) const override;
  double penaltyEnergy(const double* x, int n) const override;
  // K = -kc e_c e_c^T, D = -dc e_c e_c^T on the diagonal block of each violated wall's point.
  void addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const override;
  bool mayTouch(const double* x, int n, int lo, int hi, double reach) const override;
  // One per wall passed (or within reach): depth |x_c| - 2, gradient sign(x_c) e_c.
  int penetrations(const Vec3& x, double reach, Penetration* out) const override;
  double signedDistance(const Vec3& x) const override;  // to the nearest wall
  double stepBound(const Vec3& x, const Vec3& dx) const override;
  double depth(const Vec3& x) const override;
  bool contactBegins(const double* x0, const double* x1, int n) const override;
  int contactSprings(const Vec3& x) const override;
  void addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                         double weight, const std::array<double*, 3>& w) const override;
  // One per coordinate: 2 - |x_c|.
  int rootsPerPoint() const override { return 3; }
  void roots(const double* x, int n, double* g) const override;
};

// a*x+b*y+c*z+d = 0, solid where it is negative.
class PlaneContact final : public Obstacle {
 public:
  PlaneContact(const Plane& plane, ContactConstants k);
  ObstacleKind kind() const override { return ObstacleKind::Plane; }
  bool addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                        int hi) const override;
  double penaltyEnergy(const double* x, int n) const override;
  // K = -kc n n^T, D = -dc n n^T for each point on the solid side.
  void addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const override;
  // Depth -(n.x + offset), gradient -n.
  int penetrations(const Vec3& x, double reach, Penetration* out) const override;
  double signedDistance(const Vec3& x) const override { return side(x); }
  double stepBound(const Vec3& x, const Vec3& dx) const override;
  double depth(const Vec3& x) const override;
  bool contactBegins(const double* x0, const double* x1, int n) const override;
  int contactSprings(const Vec3& x) const override;
  void addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                         double weight, const std::array<double*, 3>& w) const override;
  // The signed distance.
  int rootsPerPoint() const override { return 1; }
  void roots(const double* x, int n, double* g) const override;
  const Vec3& normal() const { return normal_; }  // unit, into free space
  double offset() const { return offset_; }       // signed distance = normal.x + offset

 private:
  double side(const Vec3& x) const { return dot(normal_, x) + offset_; }
  Vec3 normal_;
  double offset_;
};

// Solid inside, n radial.
class SphereContact final : public Obstacle {
 public:
  SphereContact(const Sphere& sphere, ContactConstants k) : Obstacle(k), sphere_(sphere) {}
  ObstacleKind kind() const override { return ObstacleKind::Sphere; }
  const Sphere& sphere() const { return sphere_; }
  bool addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                        int hi) const override;
  double penaltyEnergy(const double* x, int n) const override;
  // For each point inside, n radial: K = -kc n n^T + kc (R/l - 1)(I - n n^T) (the second term
  // is the surface's curvature; positive, so the clamp drops it), D = -dc n n^T.
  void addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const override;
  // Depth R - l, gradient -n, Hessian -(I - n n^T)/l (at the centre: pushed up, no Hessian).
  int penetrations(const Vec3& x, double reach, Penetration* out) const override;
  double signedDistance(const Vec3& x) const override {
    return norm(x - sphere_.center) - sphere_.radius;
  }
  double stepBound(const Vec3& x, const Vec3& dx) const override;
  double depth(const Vec3& x) const override;
  bool contactBegins(const double* x0, const double* x1, int n) const override;
  int contactSprings(const Vec3& x) const override;
  void addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                         double weight, const std::array<double*, 3>& w) const override;
  // The signed distance |x - c| - R.
  int rootsPerPoint() const override { return 1; }
  void roots(const double* x, int n, double* g) const override;

 private:
  bool inside(const Vec3& x) const { return norm(x - sphere_.center) < sphere_.radius; }
  Sphere sphere_;
};

}  // namespace jello
