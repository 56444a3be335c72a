#include "src/model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "src/base/assertions.h"

namespace jello {

ModelSpec modelSpecFromWorld(const World& world) {
  ModelSpec spec;
  const Lattice lattice{world.cubeResolution};
  spec.numPoints = lattice.numPoints();
  spec.latticeResolution = lattice.n;
  spec.mass = world.mass;
  spec.springs = latticeSpringGroups(lattice, world.kElastic, world.dElastic);
  spec.contact = {world.kCollision,    world.dCollision,       world.contact.model,
                  world.contact.layer, world.contact.dhat,     world.contact.kappa,
                  world.contact.mu,    world.contact.slipSpeed};
  spec.plane = world.plane;
  spec.sphere = world.sphere;
  spec.cone = world.cone;
  spec.spiral = world.spiral;
  spec.field = world.field;
  return spec;
}

namespace {
std::atomic<long> nextModelId{0};
}  // namespace

Model::Model(ModelSpec spec)
    : id_(nextModelId.fetch_add(1, std::memory_order_relaxed)),
      n_(spec.numPoints),
      latticeResolution_(spec.latticeResolution),
      mass_(spec.mass),
      springs_(std::move(spec.springs), spec.numPoints) {
  JELLO_ASSERT(n_ > 0 && mass_ > 0.0, "a model has points of positive mass");
  JELLO_ASSERT(latticeResolution_ == 0 || Lattice{latticeResolution_}.numPoints() == n_,
               "a lattice model has resolution^3 points");
  // In the obstacle table's order (src/effects/obstacle.h).
  if (spec.walls) obstacles_.push_back(std::make_unique<WallContact>(spec.contact));
  if (spec.plane) obstacles_.push_back(std::make_unique<PlaneContact>(*spec.plane, spec.contact));
  if (spec.sphere) {
    obstacles_.push_back(std::make_unique<SphereContact>(*spec.sphere, spec.contact));
  }
  if (spec.cone) obstacles_.push_back(std::make_unique<ObstacleContact>(*spec.cone, spec.contact));
  if (spec.spiral) {
    obstacles_.push_back(std::make_unique<ObstacleContact>(*spec.spiral, spec.contact));
  }
  friction_ = spec.contact.mu > 0.0 && !obstacles_.empty();
  if (!spec.field.empty()) {
    FieldForces field(std::move(spec.field));
    if (!field.isZero()) field_.emplace(std::move(field));
  }
}

void Model::forces(const double* x, const double* v, double* f) const {
  evaluate(x, v, f, 1.0, [](std::ptrdiff_t, std::ptrdiff_t) {});
}

void Model::forces(const double* x, const double* v, double* f, PointRangeRef then) const {
  evaluate(x, v, f, 1.0, then);
}

unsigned Model::addPointForces(const double* x, const double* v, double* f, int lo, int hi) const {
  const int n = n_;
  unsigned evaluated = 0;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    if (obstacles_[i]->addForces(x, v, f, n, lo, hi)) evaluated |= 1u << i;
    if (friction_) obstacles_[i]->addFrictionForces(frictionPositions(x), v, f, n, lo, hi);
  }
  if (field_) field_->accumulate(x, f, n, lo, hi);
  if (userForce_) {
    const double* u = userForce_->data();
    for (int e = 0; e < 3; ++e)
      for (int i = e * n + lo; i < e * n + hi; ++i) f[i] += u[i];
  }
  return evaluated;
}

void Model::countEvaluation(unsigned obstaclesEvaluated) const {
  const auto count = [](std::atomic<long>& c) { c.fetch_add(1, std::memory_order_relaxed); };
  Counters& c = *counters_;
  count(c.springs);
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const auto kind = static_cast<std::size_t>(obstacles_[i]->kind());
    count((obstaclesEvaluated >> i) & 1u ? c.obstacles[kind] : c.skipped[kind]);
  }
  if (field_) count(c.field);
  if (userForce_) count(c.user);
}

EffectCounts Model::counts() const {
  const auto get = [](const std::atomic<long>& c) { return c.load(std::memory_order_relaxed); };
  const Counters& c = *counters_;
  EffectCounts out{get(c.springs), get(c.field), get(c.user), {}, {}};
  for (std::size_t k = 0; k < kObstacleKinds; ++k) {
    out.obstacles[k] = get(c.obstacles[k]);
    out.skipped[k] = get(c.skipped[k]);
  }
  return out;
}

const Obstacle* Model::obstacle(ObstacleKind kind) const {
  for (const auto& o : obstacles_) {
    if (o->kind() == kind) return o.get();
  }
  return nullptr;
}

void Model::setUserForce(const Eigen::VectorXd& f) {
  JELLO_ASSERT(f.size() == 3 * n_, "a user force holds 3n values");
  userForce_ = f;
}

void Model::acceleration(const double* x, const double* v, double* a) const {
  evaluate(x, v, a, 1.0 / mass_, [](std::ptrdiff_t, std::ptrdiff_t) {});
}

void Model::acceleration(const double* x, const double* v, double* a, PointRangeRef then) const {
  evaluate(x, v, a, 1.0 / mass_, then);
}

void Model::evaluate(const double* x, const double* v, double* f, double scale,
                     PointRangeRef then) const {
  // The springs in the two phases of src/base/parallel.h (one serial call below
  // kParallelMinPoints), then on each thread's block the rest of the forces, the scaling and
  // then().
  const std::ptrdiff_t n = n_;
  std::atomic<unsigned> evaluated{0};  // bit i: obstacle i evaluated on some block
  runOverPointBlocks(
      pointBlocks(),
      [&](std::ptrdiff_t setLo, std::ptrdiff_t setHi, std::ptrdiff_t lo, std::ptrdiff_t hi) {
        for (std::ptrdiff_t e = 0; e < 3; ++e) std::fill(f + e * n + setLo, f + e * n + setHi, 0.0);
        springs_.accumulateRange(x, v, f, lo, hi);
      },
      [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
        evaluated.fetch_or(addPointForces(x, v, f, static_cast<int>(lo), static_cast<int>(hi)),
                           std::memory_order_relaxed);
        if (scale != 1.0) {
          for (std::ptrdiff_t e = 0; e < 3; ++e)
            for (std::ptrdiff_t i = e * n + lo; i < e * n + hi; ++i) f[i] *= scale;
        }
        then(lo, hi);
      });
  countEvaluation(evaluated.load(std::memory_order_relaxed));
}

void Model::forces(const Eigen::VectorXd& x, const Eigen::VectorXd& v, Eigen::VectorXd& f) const {
  JELLO_ASSERT(x.size() == 3 * n_ && v.size() == 3 * n_, "a state holds 3n values");
  f.resize(3 * n_);
  forces(x.data(), v.data(), f.data());
}

void Model::acceleration(const Eigen::VectorXd& x, const Eigen::VectorXd& v,
                         Eigen::VectorXd& a) const {
  JELLO_ASSERT(x.size() == 3 * n_ && v.size() == 3 * n_, "a state holds 3n values");
  a.resize(3 * n_);
  acceleration(x.data(), v.data(), a.data());
}

void Model::addJacobian(const double* x, JacobianBlocks& out) const {
  if (out.includeSprings) springs_.addJacobian(x, out);
  for (const auto& o : obstacles_) {
    o->addJacobian(x, n_, out);
    if (friction_ && out.velocities) {
      o->addFrictionJacobian(frictionPositions(x), out.velocities, n_, out);
    }
  }
  if (field_) field_->addJacobian(x, n_, out);
}

bool Model::contactBegins(const double* x0, const double* x1) const {
  for (const auto& o : obstacles_) {
    if (o->contactBegins(x0, x1, n_)) return true;
  }
  return false;
}

bool Model::inContact(const double* x) const {
  for (const auto& o : obstacles_) {
    const double reach = o->reach();
    for (int p = 0; p < n_; ++p) {
      const Vec3 xp = pointAt(x, n_, p);
      if (o->depth(xp) > 0.0 || (reach > 0.0 && o->signedDistance(xp) < reach)) return true;
    }
  }
  return false;
}

bool Model::hasFriction() const {
  return friction_;
}

void Model::frictionForces(const double* x, const double* v, Eigen::VectorXd& f) const {
  f.setZero(3 * n_);
  if (!friction_) return;
  for (const auto& o : obstacles_) {
    o->addFrictionForces(frictionPositions(x), v, f.data(), n_, 0, n_);
  }
}

double Model::frictionPotential(const double* x, const double* v) const {
  if (!friction_) return 0.0;
  double potential = 0.0;
  for (const auto& o : obstacles_) potential += o->frictionPotential(frictionPositions(x), v, n_);
  return potential;
}

double Model::frictionWork(const State& from, const State& to) const {
  double power0 = 0.0, power1 = 0.0;
  for (const auto& o : obstacles_) {
    power0 += o->frictionPower(from.x.data(), from.v.data(), n_);
    power1 += o->frictionPower(to.x.data(), to.v.data(), n_);
  }
  return 0.5 * (power0 + power1) * (to.t - from.t);
}

bool Model::barrierContact() const {
  for (const auto& o : obstacles_) {
    if (o->constants().model == ContactModel::Barrier) return true;
  }
  return false;
}

double Model::minObstacleDistance(const double* x) const {
  double least = std::numeric_limits<double>::infinity();
  for (const auto& o : obstacles_) {
    for (int p = 0; p < n_; ++p) least = std::min(least, o->signedDistance(pointAt(x, n_, p)));
  }
  return least;
}

double Model::contactStepBound(const double* x, const double* dx) const {
  double bound = 1.0;
  for (const auto& o : obstacles_) {
    for (int p = 0; p < n_; ++p) {
      const Vec3 xp = pointAt(x, n_, p), dp = pointAt(dx, n_, p);
      // A point farther from the solid than it moves cannot reach it (the distance is
      // 1-Lipschitz): the cheap test first.
      if (o->signedDistance(xp) > norm(dp)) continue;
      bound = std::min(bound, o->stepBound(xp, dp));
    }
  }
  return bound;
}

namespace {

// The setting a contact problem of this obstacle comes from: the walls are the box's, their
// stiffness the constants' kCollision; the others are each an extension (the plane a flag).
std::string settingOf(ObstacleKind kind) {
  return kind == ObstacleKind::Walls ? "kCollision" : std::string(obstacleName(kind));
}

std::string joules(double e) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", e);
  return text;
}

}  // namespace

std::optional<StartProblem> Model::startProblem(const State& s) const {
  const double* x = s.x.data();
  if (barrierContact()) {
    for (const auto& o : obstacles_) {
      for (int p = 0; p < n_; ++p) {
        const double d = o->signedDistance(pointAt(x, n_, p));
        if (!(d > 0.0)) {
          return StartProblem{
              settingOf(o->kind()),
              "the barrier contact model needs every point outside every solid, but point " +
                  std::to_string(p) + " is " + (d < 0.0 ? "inside" : "on the surface of") +
                  " the " + std::string(obstacleName(o->kind())) + " (" + std::to_string(-d) +
                  " m deep)"};
        }
      }
    }
  }
  const double kinetic = 0.5 * mass_ * s.v.squaredNorm();
  if (!std::isfinite(kinetic)) {
    return StartProblem{"velocities", "the start's kinetic energy is " + joules(kinetic) +
                                          " J: every term of the energy must be finite"};
  }
  if (const double e = springs_.energy(x); !std::isfinite(e)) {
    return StartProblem{"kElastic", "the springs' energy at the start is " + joules(e) +
                                        " J: every term of the energy must be finite"};
  }
  for (const auto& o : obstacles_) {
    if (const double e = o->energy(x, n_); !std::isfinite(e)) {
      const std::string name(obstacleName(o->kind()));
      return StartProblem{settingOf(o->kind()),
                          "the " + name + "'s contact energy at the start is " + joules(e) +
                              " J (the cube starts deep inside the " + name +
                              "): every term of the energy must be finite"};
    }
  }
  return std::nullopt;
}

WorldFileError startError(const StartProblem& problem, const World& world,
                          const std::string& file) {
  if (const SourcePlace* place = world.sourceOf(problem.what)) {
    return WorldFileError(file, place->line, place->token, problem.message);
  }
  return WorldFileError(file, 0, problem.what, problem.message);
}

void checkStart(const World& world, const std::string& file) {
  if (const std::optional<StartProblem> problem = Model(world).startProblem(initialState(world))) {
    throw startError(*problem, world, file);
  }
}

double Model::userForceWork(const Eigen::VectorXd& x0, const Eigen::VectorXd& x1) const {
  return userForce_ ? userForce_->dot(x1 - x0) : 0.0;
}

double Model::fieldWork(const double* x0, const double* x1) const {
  if (!field_) return 0.0;
  const int n = n_;
  double work = 0.0;
  for (int p = 0; p < n; ++p) {
    const Vec3 a{x0[p], x0[n + p], x0[2 * n + p]}, b{x1[p], x1[n + p], x1[2 * n + p]};
    work += 0.5 * dot(field_->sample(a) + field_->sample(b), b - a);
  }
  return work;
}

Vec3 Model::angularMomentum(const State& s) const {
  const int n = n_;
  const Vec3 c = s.centroid();
  Vec3 L;
  for (int p = 0; p < n; ++p) {
    const Vec3 r = s.position(p) - c, v = s.velocity(p);
    L = L + Vec3{r.y * v.z - r.z * v.y, r.z * v.x - r.x * v.z, r.x * v.y - r.y * v.x};
  }
  return L * mass_;
}

double Model::potentialEnergy(const double* x) const {
  double e = springs_.energy(x);
  for (const auto& o : obstacles_) e += o->energy(x, n_);
  return e;
}

void Model::externalForces(const double* x, Eigen::VectorXd& f) const {
  f.setZero(3 * n_);
  if (field_) field_->accumulate(x, f.data(), n_);
  if (userForce_) f += *userForce_;
}

Energy Model::energy(const Eigen::VectorXd& x, const Eigen::VectorXd& v) const {
  Energy e;
  e.kinetic = 0.5 * mass_ * v.squaredNorm();
  e.spring = springs_.energy(x.data());
  for (const auto& o : obstacles_) e.contact += o->energy(x.data(), n_);
  return e;
}

}  // namespace jello
