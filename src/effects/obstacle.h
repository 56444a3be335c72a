// The solids a point can be pushed out of, one interface (house style: a closed set is one
// table). Each obstacle is a geometry with contact by one of the laws of src/world/
// contact_law.h (src/PHYSICS.md): a point on the solid side of its surface, at depth q, has
//   energy = e(q),   f = -e'(q) grad(q) - dc w(q) (n.v) n,
// with n the unit normal into free space; the course's penalty is e = 1/2 kc q^2 and w = 1 (a
// rest-length-0 spring to the surface), the smooth law rises over a layer (contact_law.h) with
// w = e''/kc, so its damping starts from 0 at the surface as its stiffness does; the barrier is
// a law in the signed depth q = -d within dhat outside the solid (d the exact distance), with
// no damping (w = 0) and infinite energy at d <= 0, which the implicit methods' step bounds keep
// every point from reaching (stepBound). It answers every
// question the model and the solvers ask of contact (forces, energy, Jacobian, depth, onset, the
// contact weights of the projective matrices, CVODE's root functions), so Model, solvers/cvode/,
// solvers/system/implicit_system.cpp and solvers/methods/projective_integrator.cpp iterate
// Model::obstacles() and name none of them. The implementations: walls, plane and sphere in
// contact.h, cone and spiral in obstacles.h.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>

#include "src/base/vec3.h"
#include "src/effects/jacobian_blocks.h"
#include "src/world/contact_law.h"

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
  ContactModel model = ContactModel::Penalty;
  double layer = 0.0;      // m, the smooth law's layer
  double dhat = 0.0;       // m, the barrier's reach
  double kappa = 0.0;      // N/m, the barrier's stiffness scale
  double mu = 0.0;         // Coulomb friction's coefficient; 0: none
  double slipSpeed = 0.0;  // m/s, eps_v: where static friction has turned kinetic
};

// Coulomb friction smoothed over the slip speed eps (IPC's mollifier, src/PHYSICS.md) at slip
// speed s = |u|, u the tangential velocity: f1(s) = 2 s/eps - s^2/eps^2 below eps, 1 above,
// so the force -mu lambda f1(s) u/s grows from 0 like a stiff damper (static friction) to
// Coulomb's mu lambda; g = f1/s and g' its derivative in s (the force is -mu lambda g u, its
// velocity Jacobian -mu lambda (g T + g' u u^T/s), T = I - n n^T).
struct FrictionValue {
  double f1 = 0.0, g = 0.0, dg = 0.0;
};
FrictionValue smoothedFriction(double slip, double slipSpeed);

// A contact's depth e(q) law at depth q > 0: energy (J), its first derivative (N: the force's
// magnitude along the depth's gradient) and second (N/m: the stiffness along it).
struct ContactLawValue {
  double energy = 0.0;
  double force = 0.0;
  double stiffness = 0.0;
};
// The smooth law (src/world/contact_law.h): q < layer: kc q^3 / (6 layer); beyond, the
// quadratic with the same value, slope and curvature at q = layer, kc/2 (q - layer/2)^2 +
// kc layer^2 / 24. Its energy is C2 in q, 0 with its derivatives at the surface.
ContactLawValue smoothContactLaw(double depth, double stiffness, double layer);
// The barrier (Li et al. 2020) in the signed depth q = -d: b(d) = -kappa (d - dhat)^2 ln(d/dhat)
// for 0 < d < dhat, 0 beyond; its q-derivatives -b'(d) and b''(d). At d <= 0 all three are +inf.
ContactLawValue barrierContactLaw(double depth, double kappa, double dhat);

// One contact of a point: how deep it is inside a solid, and the depth's derivatives.
struct Penetration {
  double depth = 0.0;                               // m, > 0 inside; -distance outside
  Vec3 gradient;                                    // of the depth (points into the solid)
  double hessian[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};  // row-major, of the depth
};
// At most this many contacts per point and obstacle (the walls: one per axis).
inline constexpr int kMaxPenetrations = 3;

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
  bool addForces(const double* x, const double* v, double* f, int n, int lo, int hi) const {
    return k_.model == ContactModel::Penalty ? addPenaltyForces(x, v, f, n, lo, hi)
                                             : addLawForces(x, v, f, n, lo, hi);
  }
  // The same for all n points.
  void accumulate(const double* x, const double* v, double* f, int n) const {
    addForces(x, v, f, n, 0, n);
  }
  // The contact energy (J) of all n points.
  double energy(const double* x, int n) const {
    return k_.model == ContactModel::Penalty ? penaltyEnergy(x, n) : lawEnergy(x, n);
  }
  // K = df/dx and D = df/dv on each touching point's diagonal block (src/effects/
  // jacobian_blocks.h): K = -(e'' g g^T + e' Hess(q)) + dc vn w'(q) |g| n n^T, D = -dc w n n^T;
  // under the clamp the curvature term e' Hess(q) and the weight's term moving out (vn > 0)
  // are dropped; the weight's term and friction's D only where out gives the velocities.
  void addJacobian(const double* x, int n, JacobianBlocks& out) const {
    if (k_.model == ContactModel::Penalty) {
      addPenaltyJacobian(x, n, out);
    } else {
      addLawJacobian(x, n, out);
    }
  }
  // Friction (src/effects/friction.cpp): on each contact with normal force lambda > 0 (the
  // law's elastic part e'(q), no damping), normal n and tangential velocity u = (I - n n^T) v,
  //   f = -mu lambda f1(|u|) u/|u|,   D = df/dv = -mu lambda (g T + g' u u^T/|u|),
  // D symmetric and negative semidefinite. lambda and n come from positions `at` (3n): the
  // state's own, or where the model lags them (Model::FrictionLag); their derivatives in x are
  // never in K. Nothing without friction (mu = 0).
  void addFrictionForces(const double* at, const double* v, double* f, int n, int lo, int hi) const;
  void addFrictionJacobian(const double* at, const double* v, int n, JacobianBlocks& out) const;
  // Friction's power, sum f.v over all n points (W, <= 0): the rate at which it dissipates.
  double frictionPower(const double* x, const double* v, int n) const;
  // Friction's dissipation potential (W) with lambda and n from positions x: sum of
  // mu lambda F0(|u|), F0' = f1 (s^2/eps - s^3/(3 eps^2), then s - eps/3), so f = -dF/dv; convex.
  double frictionPotential(const double* x, const double* v, int n) const;

  // Writes each contact x has with this solid (at most kMaxPenetrations) to out; returns how
  // many. With reach > 0 also those outside, within reach of the surface: their depth is minus
  // their distance to it (exact; the spiral's a lower bound, obstacles.h).
  virtual int penetrations(const Vec3& x, double reach, Penetration* out) const = 0;
  int penetrations(const Vec3& x, Penetration* out) const { return penetrations(x, 0.0, out); }
  // How far outside the law reaches: the barrier's dhat, 0 for the others.
  double reach() const { return k_.model == ContactModel::Barrier ? k_.dhat : 0.0; }
  // The signed distance from x to the solid (m): > 0 outside, exact (the walls: to the nearest
  // wall; the spiral: a lower bound, obstacles.h); -depth inside.
  virtual double signedDistance(const Vec3& x) const = 0;
  // The largest s in [0, 1] such that x + t dx stays outside the solid for t in [0, s), x
  // outside: closed form for walls, plane and sphere; conservative advancement on the distance
  // for the cone (exact) and the spiral (a lower bound, so no advancement overshoots), within
  // 1e-9 m of the surface.
  virtual double stepBound(const Vec3& x, const Vec3& dx) const;

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
  // The course's penalty, written out per solid (vectorized where it runs in every force
  // evaluation); the other laws go through penetrations().
  virtual bool addPenaltyForces(const double* x, const double* v, double* f, int n, int lo,
                                int hi) const = 0;
  virtual double penaltyEnergy(const double* x, int n) const = 0;
  virtual void addPenaltyJacobian(const double* x, int n, JacobianBlocks& out) const = 0;
  // False when no point of [lo, hi) can touch (a cheap check; the walls').
  virtual bool mayTouch(const double* /*x*/, int /*n*/, int /*lo*/, int /*hi*/,
                        double /*reach*/) const {
    return true;
  }

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
  // The law's value at depth q (not the penalty's, which has its own loops).
  ContactLawValue law(double depth) const;
  struct FrictionContact {
    double bound = 0.0;  // N: mu lambda
    Vec3 normal;
    Vec3 slip;  // m/s: u
  };
  // The friction contacts of point p at (x, v), written to out; how many.
  int frictionContacts(const double* x, const double* v, int n, int p, FrictionContact* out) const;
  // The elastic normal force's magnitude (N) of a contact at depth q under the scene's law.
  double normalForce(double depth) const;
  double dampingWeight(const ContactLawValue& e) const;
  // dw/dq at depth q: 1/layer inside the smooth law's layer, else 0.
  double dampingWeightSlope(double depth) const;
  bool addLawForces(const double* x, const double* v, double* f, int n, int lo, int hi) const;
  double lawEnergy(const double* x, int n) const;
  void addLawJacobian(const double* x, int n, JacobianBlocks& out) const;

  ContactConstants k_;
};

}  // namespace jello
