// The physical model of a scene: n equal point masses and the effects the scene has.
//   a = (sum of forces) / m
// Effects: elastic springs (always), the obstacles (src/effects/obstacle.h: the walls of the
// box [-2,2]^3, skipped in a block of points that are all inside, and only when the scene has
// them the inclined plane, the sphere, the cone and the spiral ramp), the force field (an
// all-zero field is dropped, a uniform one is a constant force) and a user force. This is the
// one seam integrators use: forces/acceleration of a state, its Jacobians, and its energy.
#pragma once

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "src/base/parallel.h"
#include "src/effects/contact.h"
#include "src/effects/force_field.h"
#include "src/effects/obstacles.h"
#include "src/effects/spring_forces.h"
#include "src/state.h"
#include "src/world/world.h"
#include "src/world/world_reader.h"

namespace jello {

struct ModelSpec {
  int numPoints = 0;
  // Points per edge when the points are a Lattice's, in its order (src/world/lattice.h); 0 when
  // they are not (a test's few points). Solvers may use the lattice's structure.
  int latticeResolution = 0;
  double mass = 0.0;  // kg, of each point
  std::vector<SpringGroup> springs;
  bool walls = true;
  ContactConstants contact;
  std::optional<Plane> plane;
  std::optional<Sphere> sphere;
  std::optional<Cone> cone;
  std::optional<Spiral> spiral;
  ForceField field;
};

// The lattice springs and every effect the world file describes.
ModelSpec modelSpecFromWorld(const World& world);

struct Energy {
  double kinetic = 0.0;  // J
  double spring = 0.0;   // J, elastic springs
  double contact = 0.0;  // J, penalty springs of every obstacle
  double total() const { return kinetic + spring + contact; }
};

// Why a simulation cannot start: the setting to blame, as World::sourceOf names it
// ("kElastic", "kCollision", "plane", "sphere", "cone", "spiral", "contact", or "velocities"),
// and what is wrong.
struct StartProblem {
  std::string what;
  std::string message;
};

// The problem as the reader reports a bad file: the file, and the line and token where the
// world set `what` (line 0 and the file's name when it did not come from a file).
WorldFileError startError(const StartProblem& problem, const World& world, const std::string& file);
// Throws startError when a simulation of `world` (read from `file`) could not start: for
// programs that load a world and step it later (the viewer).
void checkStart(const World& world, const std::string& file);

// How often each effect was evaluated: lets tests check that absent effects cost nothing.
// A snapshot of the model's counters, which are atomic (threads may share a model).
struct EffectCounts {
  long springs = 0;
  long field = 0;
  long user = 0;
  // Per obstacle kind: evaluations, and those skipped because no point touched (the walls').
  std::array<long, kObstacleKinds> obstacles{};
  std::array<long, kObstacleKinds> skipped{};
  long of(ObstacleKind kind) const { return obstacles[static_cast<std::size_t>(kind)]; }
  long skippedOf(ObstacleKind kind) const { return skipped[static_cast<std::size_t>(kind)]; }
};

class Model {
 public:
  explicit Model(ModelSpec spec);
  explicit Model(const World& world) : Model(modelSpecFromWorld(world)) {}

  int numPoints() const { return n_; }
  // Unique to this model among all models built in the process (moves carry it along):
  // integrators bind to a model by it, never by its address, which a new model may reuse.
  long id() const { return id_; }
  double mass() const { return mass_; }
  int latticeResolution() const { return latticeResolution_; }  // ModelSpec's

  // f = total force (N) at state (x, v); all arrays 3n, component-major. The model keeps no
  // scratch: several threads may evaluate one model at once (only its counters change, and
  // they are atomic). Split over threads as the acceleration with then() below is.
  void forces(const double* x, const double* v, double* f) const;
  // a = f / m (m/s^2).
  void acceleration(const double* x, const double* v, double* a) const;
  // The same, then then(lo, hi) on ranges of points whose acceleration is final, each point in
  // one range: a step's update of those points fused with the evaluation. From
  // kParallelMinPoints points up the work is split over threads by blocks of points
  // (src/base/parallel.h, runOverPointBlocks): a thread computes its block's forces, contact and
  // acceleration and runs then() on them, so what one stage writes stays in that core's cache
  // for the next (updates on one thread between threaded evaluations made a 32^3 RK4 step
  // little faster on two).
  // then() may write x and v at [lo, hi) (no longer read there), and nothing outside it.
  void acceleration(const double* x, const double* v, double* a, PointRangeRef then) const;
  // The forces, then then(lo, hi) on the same ranges once f is final there (projective's
  // residual and contact weights ride along).
  void forces(const double* x, const double* v, double* f, PointRangeRef then) const;
  // The same on Eigen vectors; the output is resized.
  void forces(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& f) const;
  void acceleration(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& a) const;

  // True when some point is in contact with some obstacle at positions x1 but was not at x0:
  // the contact set changed between them.
  bool contactBegins(const double* x0, const double* x1) const;
  // True when some point is in contact with some obstacle at positions x (for the barrier:
  // within its reach dhat).
  bool inContact(const double* x) const;
  // True when contact is the barrier (src/world/contact_law.h): no point may reach a solid.
  bool barrierContact() const;
  // The least signed distance (m) of any point to any solid at positions x: < 0 when one is
  // inside (Obstacle::signedDistance); +inf without solids.
  double minObstacleDistance(const double* x) const;
  // The largest s in [0, 1] for which no point moving from x along s dx (3n each) reaches a
  // solid (Obstacle::stepBound): the barrier's line-search bound.
  double contactStepBound(const double* x, const double* dx) const;
  // Why this model cannot step from state s, or nothing: the barrier needs every point
  // outside every solid, and every term of the start's
  // energy must be finite (a cube deep inside a sphere of radius 1e308 would start with an
  // infinite contact energy that the implicit methods then ignore).
  std::optional<StartProblem> startProblem(const State& s) const;

  // Work (J) the force field does on the points moving from x0 to x1 (3n each), by the
  // trapezoid rule along the straight path: sum of 1/2 (F(x0) + F(x1)) . (x1 - x0). Exact for
  // a uniform field; 0 without a field.
  double fieldWork(const double* x0, const double* x1) const;
  // True when contact has Coulomb friction (mu > 0).
  bool hasFriction() const;
  // While one lives, friction's normal forces and normals (Obstacle::addFrictionForces) come
  // from positions x (3n, alive as long) instead of each evaluated state's: the implicit
  // methods lag them at their step's start (IPC), so that within the step friction is the
  // gradient of a dissipation potential in v and Newton converges on it (lagged per iterate,
  // the normal force's pull on the slip, left out of K, made Newton creep: 100+ iterations a
  // step on a cube resting on a slope). One at a time per model; the explicit methods and
  // cvode evaluate friction at each state.
  class FrictionLag {
   public:
    FrictionLag(const Model& model, const double* x) : model_(model) { model_.frictionAt_ = x; }
    ~FrictionLag() { model_.frictionAt_ = nullptr; }
    FrictionLag(const FrictionLag&) = delete;
    FrictionLag& operator=(const FrictionLag&) = delete;

   private:
    const Model& model_;
  };
  // Friction's forces alone at (x, v) (N, f resized to 3n; zero without friction): what the
  // viewer draws.
  void frictionForces(const double* x, const double* v, Eigen::VectorXd& f) const;
  // Friction's dissipation potential (W) at velocities v, lambda and n from positions x or the
  // lag (Obstacle::frictionPotential): with the lag, the force is minus its gradient in v.
  double frictionPotential(const double* x, const double* v) const;
  // Work (J) friction does over a step of h from (x0, v0) to (x1, v1), by the trapezoid rule on
  // its power (Obstacle::frictionPower): <= 0, what it dissipated; 0 without friction.
  double frictionWork(const State& from, const State& to) const;
  // Work (J) of the user force (constant) over the move from x0 to x1; 0 without one.
  double userForceWork(const Eigen::VectorXd& x0, const Eigen::VectorXd& x1) const;

  Energy energy(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const;
  // Angular momentum about the centre of mass (kg m^2/s).
  Vec3 angularMomentum(const State& s) const;
  // Spring plus contact energy (J) at positions x (3n): the potential of the elastic forces.
  double potentialEnergy(const double* x) const;
  // The forces no potential above describes, f resized to 3n (N): the field and the user force
  // at positions x. Zero when the scene has neither.
  void externalForces(const double* x, Eigen::VectorXd& f) const;
  Energy energy(const State& s) const { return energy(s.x, s.v); }

  // Adds every effect's Jacobian blocks at positions x (src/effects/jacobian_blocks.h): the
  // springs, and the walls, plane, sphere and field where the scene has them. The user force is
  // constant and adds nothing.
  void addJacobian(const double* x, JacobianBlocks& out) const;

  const SpringForces& springs() const { return springs_; }
  // The scene's obstacles, in the order of the obstacle table (src/effects/obstacle.h): what
  // CVODE's roots, the implicit system and projective's contact weights iterate.
  const std::vector<std::unique_ptr<Obstacle>>& obstacles() const { return obstacles_; }
  // The obstacle of that kind, or null when the scene has none.
  const Obstacle* obstacle(ObstacleKind kind) const;
  bool has(ObstacleKind kind) const { return obstacle(kind) != nullptr; }
  const std::optional<FieldForces>& field() const { return field_; }
  bool hasField() const { return field_.has_value(); }
  EffectCounts counts() const;

  // A force a user applies from outside (the viewer's mouse drag): f (N), 3n component-major,
  // constant in x and v, so it adds nothing to the Jacobians. Absent until set; clearing it
  // drops the effect again. Integrators that carry history must be told (Simulation does).
  void setUserForce(const Eigen::VectorXd& f);
  void clearUserForce() { userForce_.reset(); }
  bool hasUserForce() const { return userForce_.has_value(); }

  // How the model splits its points over threads (src/base/parallel.h): acceleration()'s then()
  // runs on these blocks, so a caller's pass over the same blocks finds its data in its core.
  PointBlocks pointBlocks() const {
    return splitPointBlocks(n_, springs_.reach(), springs_.threads());
  }

 private:
  // f = scale x (the forces at (x, v)), then then() on each block of points once f is final
  // there: forces() and both acceleration()s.
  void evaluate(const double* x, const double* v, double* f, double scale,
                PointRangeRef then) const;
  // Adds every effect but the springs at the points [lo, hi) to f; bit i of the result: the
  // i-th obstacle evaluated them (not skipped).
  unsigned addPointForces(const double* x, const double* v, double* f, int lo, int hi) const;
  // Counts one evaluation of every effect the scene has (bit i: obstacle i was not skipped).
  void countEvaluation(unsigned obstaclesEvaluated) const;

  long id_;
  int n_;
  int latticeResolution_;
  double mass_;
  SpringForces springs_;
  std::vector<std::unique_ptr<Obstacle>> obstacles_;
  std::optional<FieldForces> field_;
  std::optional<Eigen::VectorXd> userForce_;
  bool friction_ = false;
  mutable const double* frictionAt_ = nullptr;  // FrictionLag's positions, or none
  // Where friction takes its normal forces from at positions x: the lag's, else x.
  const double* frictionPositions(const double* x) const { return frictionAt_ ? frictionAt_ : x; }
  struct Counters {
    std::atomic<long> springs{0}, field{0}, user{0};
    std::array<std::atomic<long>, kObstacleKinds> obstacles{}, skipped{};
  };
  // unique_ptr keeps the model movable; relaxed increments: counts, not synchronization.
  std::unique_ptr<Counters> counters_ = std::make_unique<Counters>();
};

}  // namespace jello
