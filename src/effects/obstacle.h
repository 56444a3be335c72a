// The solids a point can be pushed out of, one interface (house style: a closed set is one
// table). Each obstacle is a geometry with the course's penalty contact (src/PHYSICS.md): a
// point on the solid side of its surface gets a rest-length-0 spring to it,
//   energy = 1/2 kc depth^2,   f = -kc depth grad(depth) - dc (n.v) n,
// and answers every question the model and the solvers ask of contact (forces, energy,
// Jacobian, depth, onset, the contact weights of the projective matrices, CVODE's root
// functions), so Model, solvers/cvode/, solvers/system/implicit_system.cpp and
// solvers/methods/projective_integrator.cpp iterate Model::obstacles() and name none of them.
// The implementations: walls, plane and sphere in contact.h, cone and spiral in obstacles.h.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>

#include "src/base/vec3.h"
#include "src/effects/jacobian_blocks.h"

namespace jello {

// Each row: enumerator, name (statistics, messages). The order is the model's.
#define JELLO_OBSTACLES(X) \
  X(Walls, "walls")        \
  X(Plane, "plane")        \
  X(Sphere, "sphere")      \
  X(Cone, "cone")          \
  X(Spiral, "spiral")

enum class ObstacleKind {
#define JELLO_OBSTACLE_ENUMERATOR(kind, name) kind,
  JELLO_OBSTACLES(JELLO_OBSTACLE_ENUMERATOR)
#undef JELLO_OBSTACLE_ENUMERATOR
};
inline constexpr std::size_t kObstacleKinds = 0
#define JELLO_OBSTACLE_COUNT(kind, name) +1
    JELLO_OBSTACLES(JELLO_OBSTACLE_COUNT)
#undef JELLO_OBSTACLE_COUNT
    ;
std::string_view obstacleName(ObstacleKind kind);

struct ContactConstants {
  double stiffness = 0.0;  // N/m (kCollision)
  double damping = 0.0;    // N*s/m (dCollision)
};

// All arrays are 3n, component-major (x of every point, then y, then z); [lo, hi) a range of
// points (Model splits them over threads).
class Obstacle {
 public:
  explicit Obstacle(ContactConstants k) : k_(k) {}
  virtual ~Obstacle() = default;
  virtual ObstacleKind kind() const = 0;
  const ContactConstants& constants() const { return k_; }

  // Adds the contact forces (N) of the points [lo, hi) to f. False when it skipped them all
  // after a cheap check that none touches (the walls'; the others always evaluate).
  virtual bool addForces(const double* x, const double* v, double* f, int n, int lo,
                         int hi) const = 0;
  // The same for all n points.
  void accumulate(const double* x, const double* v, double* f, int n) const {
    addForces(x, v, f, n, 0, n);
  }
  // The contact energy (J) of all n points.
  virtual double energy(const double* x, int n) const = 0;
  // K = df/dx and D = df/dv on each touching point's diagonal block (src/effects/
  // jacobian_blocks.h); the curvature term is dropped under the clamp.
  virtual void addJacobian(const double* x, int n, JacobianBlocks& out) const = 0;

  // How deep x is inside the solid (m): > 0 in contact, 0 in free space (the walls: the
  // deepest of the walls it passed).
  virtual double depth(const Vec3& x) const = 0;
  // True when a contact spring of some point exists at positions x1 but did not at x0.
  virtual bool contactBegins(const double* x0, const double* x1, int n) const = 0;
  // The contact springs x has with this solid (walls: one per wall passed, each along its
  // axis; the others 0 or 1).
  virtual int contactSprings(const Vec3& x) const = 0;
  // Adds `weight` per contact spring of the points [lo, hi) to w[c][p], for each coordinate c
  // the spring's direction reaches: a wall's its own axis alone, the others' all three (their
  // n n^T <= I). Projective's diagonal contact weights.
  virtual void addContactWeights(const double* x, int n, std::ptrdiff_t lo, std::ptrdiff_t hi,
                                 double weight, const std::array<double*, 3>& w) const = 0;

  // CVODE's root functions: per point, functions of x that change sign where a contact begins
  // or ends, > 0 in free space (none where the solid has no distance outside it yet).
  virtual int rootsPerPoint() const { return 0; }
  // Writes rootsPerPoint() * n values to g.
  virtual void roots(const double* /*x*/, int /*n*/, double* /*g*/) const {}

 protected:
  // addContactWeights of a solid whose spring reaches every coordinate: w[c][p] += weight on
  // all three where inside(p), p in [lo, hi).
  template <class Inside>
  static void addToAllCoordinates(std::ptrdiff_t lo, std::ptrdiff_t hi, double weight,
                                  const std::array<double*, 3>& w, const Inside& inside) {
    for (std::ptrdiff_t p = lo; p < hi; ++p) {
      if (!inside(p)) continue;
      for (int c = 0; c < 3; ++c) w[c][p] += weight;
    }
  }

 private:
  ContactConstants k_;
};

}  // namespace jello
