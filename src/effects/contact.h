// Penalty contact (src/PHYSICS.md): a point on the solid side of a surface gets a rest-length-0
// spring to its projection p on the surface,
//   f = -kc (n.(x - p)) n - dc (n.v) n,   energy = 1/2 kc (n.(x - p))^2,
// with n the unit normal pointing into free space. Walls: the six faces of the box [-2,2]^3,
// one spring per violated wall. Plane: a*x+b*y+c*z+d = 0, solid where it is negative. Sphere:
// solid inside, n radial.
#pragma once

#include "src/effects/jacobian_blocks.h"
#include "src/world/world.h"

namespace jello {

inline constexpr double kBoxHalfSize = 2.0;  // m: the box is [-2,2]^3

struct ContactConstants {
  double stiffness = 0.0;  // N/m (kCollision)
  double damping = 0.0;    // N*s/m (dCollision)
};

// All arrays component-major, n points. The forces' range versions add those of the points
// [lo, hi) only (Model splits them over threads).
class WallContact {
 public:
  explicit WallContact(ContactConstants k) : k_(k) {}
  const ContactConstants& constants() const { return k_; }
  // True when every point (of [lo, hi)) is inside the box, so there is nothing to do.
  static bool allInside(const double* x, int n) { return allInside(x, n, 0, n); }
  static bool allInside(const double* x, int n, int lo, int hi);
  void accumulate(const double* x, const double* v, double* f, int n) const {
    accumulate(x, v, f, n, 0, n);
  }
  void accumulate(const double* x, const double* v, double* f, int n, int lo, int hi) const;
  double energy(const double* x, int n) const;
  // K = -kc e_c e_c^T, D = -dc e_c e_c^T on the diagonal block of each violated wall's point.
  void addJacobian(const double* x, int n, JacobianBlocks& out) const;

 private:
  ContactConstants k_;
};

class PlaneContact {
 public:
  PlaneContact(const Plane& plane, ContactConstants k);
  void accumulate(const double* x, const double* v, double* f, int n) const {
    accumulate(x, v, f, n, 0, n);
  }
  void accumulate(const double* x, const double* v, double* f, int n, int lo, int hi) const;
  double energy(const double* x, int n) const;
  // K = -kc n n^T, D = -dc n n^T for each point on the solid side.
  void addJacobian(const double* x, int n, JacobianBlocks& out) const;
  const Vec3& normal() const { return normal_; }  // unit, into free space
  double offset() const { return offset_; }       // signed distance = normal.x + offset
  const ContactConstants& constants() const { return k_; }

 private:
  Vec3 normal_;
  double offset_;
  ContactConstants k_;
};

class SphereContact {
 public:
  SphereContact(const Sphere& sphere, ContactConstants k) : sphere_(sphere), k_(k) {}
  const Sphere& sphere() const { return sphere_; }
  const ContactConstants& constants() const { return k_; }
  void accumulate(const double* x, const double* v, double* f, int n) const {
    accumulate(x, v, f, n, 0, n);
  }
  void accumulate(const double* x, const double* v, double* f, int n, int lo, int hi) const;
  double energy(const double* x, int n) const;
  // For each point inside, n radial: K = -kc n n^T + kc (R/l - 1)(I - n n^T) (the second term
  // is the surface's curvature; positive, so the clamp drops it), D = -dc n n^T.
  void addJacobian(const double* x, int n, JacobianBlocks& out) const;

 private:
  Sphere sphere_;
  ContactConstants k_;
};

}  // namespace jello
