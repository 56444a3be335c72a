#include "experiments/studies/atlas.h"

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "experiments/studies/reference_file.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study_integrators.h"
#include "experiments/studies/trajectory_run.h"
#include "solvers/simulation.h"
#include "src/base/closed_set.h"
#include "src/base/parallel.h"
#include "src/world/integrator_table.h"
#include "src/world/lattice.h"
#include "src/world/scene_builder.h"

namespace jello::experiments {

using Fit = Eigen::Matrix<double, 3, 4>;

namespace {

constexpr closed_set::Row<AtlasScene> kScenes[] = {
    {AtlasScene::Falling, "falling",
     "cube at rest shape thrown at 0.5 m/s and spinning 2 rad/s about z, falling 1.5 m onto the "
     "floor under gravity, c = 0.25 N*s/m"},
    {AtlasScene::Free, "free",
     "cube at rest shape thrown at 0.5 m/s and spinning 2 rad/s about z, no gravity, touching "
     "nothing within the window, c = 0.25 N*s/m"},
    {AtlasScene::Slide, "slide",
     "cube at rest shape set 2 cm above a 20 degree incline and thrown down it at 1 m/s under "
     "gravity; Coulomb friction mu = 0.6 (slip speed 1 mm/s) on every solid: it lands, slides "
     "and comes to rest; c = 0.25 N*s/m"},
};

constexpr double kSlideDegrees = 20.0, kSlideMu = 0.6, kSlideDrop = 0.02, kSlideSpeed = 1.0;
constexpr double kGravity = 9.81;  // m/s^2, defaultFieldStrength's

}  // namespace

std::optional<AtlasScene> parseAtlasScene(const std::string& name) {
  return closed_set::parse(kScenes, name);
}

std::string sceneName(AtlasScene scene) {
  return std::string(closed_set::row(kScenes, scene).name);
}

std::vector<std::string> sceneNames() {
  std::vector<std::string> names;
  for (const auto& row : kScenes) names.emplace_back(row.name);
  return names;
}

std::string describe(AtlasScene scene) {
  return std::string(closed_set::row(kScenes, scene).summary);
}

Vec3 slideNormal() {
  const double theta = kSlideDegrees * 3.14159265358979323846 / 180.0;
  return {std::sin(theta), 0.0, std::cos(theta)};
}

Vec3 slideDownhill() {
  const double theta = kSlideDegrees * 3.14159265358979323846 / 180.0;
  return {std::cos(theta), 0.0, -std::sin(theta)};
}

std::optional<AtlasContact> parseAtlasContact(const std::string& name) {
  if (name == "soft") return AtlasContact::Soft;
  if (name == "k") return AtlasContact::AsStiff;
  if (name == "20k") return AtlasContact::Stiffer;
  return std::nullopt;
}

std::string contactName(AtlasContact contact) {
  switch (contact) {
    case AtlasContact::Soft:
      return "soft";
    case AtlasContact::AsStiff:
      return "k";
    case AtlasContact::Stiffer:
      return "20k";
  }
  return "soft";
}

double contactStiffness(AtlasContact contact, double k) {
  switch (contact) {
    case AtlasContact::Soft:
      return 400.0;  // the course's kCollision
    case AtlasContact::AsStiff:
      return k;
    case AtlasContact::Stiffer:
      return 20.0 * k;
  }
  return 400.0;
}

std::string referenceSceneName(AtlasScene scene, AtlasContact contact) {
  return contact == AtlasContact::Soft ? sceneName(scene)
                                       : sceneName(scene) + "-contact-" + contactName(contact);
}

namespace {

// The incline through (0, 0, -1.3) descending along x (it meets the floor at x = 1.92); the cube
// aligned with it, its bottom face's centre kSlideDrop above the incline over x = -1.2, moving
// downhill along the fall line, without spin.
World slideScene(SceneSpec spec) {
  const Vec3 n = slideNormal(), t = slideDownhill(), e{0.0, 1.0, 0.0};
  const Vec3 through{0.0, 0.0, -1.3};
  spec.plane = Plane{n.x, n.y, n.z, -dot(n, through)};
  spec.contact.mu = kSlideMu;
  spec.velocity = {0.0, 0.0, 0.0};
  spec.spin = 0.0;
  World w = buildWorld(spec);
  const Vec3 foot = through + t * (-1.2 / t.x);  // on the incline, at x = -1.2
  for (std::size_t i = 0; i < w.positions.size(); ++i) {
    const Vec3 r = w.positions[i] - Vec3{0.5, 0.5, 0.0};  // from the bottom face's centre
    w.positions[i] = foot + t * r.x + e * r.y + n * (r.z + kSlideDrop);
    w.velocities[i] = t * kSlideSpeed;
  }
  return w;
}

}  // namespace

World atlasScene(double k, int n, AtlasScene scene, AtlasContact contact) {
  SceneSpec spec = stiffCube(k);  // c = 0.25 N*s/m, no plane
  spec.cubeResolution = n;
  spec.pose = PosePreset::Rest;
  spec.velocity = {0.5, 0.0, 0.0};
  spec.spin = 2.0;  // slideScene sets its own
  if (scene != AtlasScene::Free) {
    spec.field = FieldPreset::Gravity;
    spec.fieldStrength = defaultFieldStrength(FieldPreset::Gravity, spec.mass);
    spec.fieldResolution = 2;  // uniform
  } else {
    spec.fieldResolution = 0;
  }
  spec.kCollision = contactStiffness(contact, k);
  if (scene == AtlasScene::Slide) return slideScene(spec);
  World w = buildWorld(spec);
  // Centred in the box: falling, 1.5 m above the floor (z = -2), reached after about 0.55 s;
  // free, 1 s of drift moves it 0.5 m, its corners (0.87 m from the centre) stay 0.6 m from
  // the walls.
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};
  return w;
}

VisibleMotion::VisibleMotion(int n) {
  const Lattice lattice{n};
  Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Vec3 p = lattice.restPosition(i, j, k);
        const Eigen::Vector3d r(p.x - 0.5, p.y - 0.5, p.z - 0.5);
        rest_.push_back(r);
        gram += r * r.transpose();
      }
    }
  }
  inverseGram_ = gram.inverse();
}

Fit VisibleMotion::fit(const State& s) const {
  // rest_ is in the lattice's point order (Lattice::index).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int p = 0; p < s.numPoints(); ++p) {
    const Vec3 x = s.position(p);
    mean += Eigen::Vector3d(x.x, x.y, x.z);
  }
  mean /= double(s.numPoints());
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (int p = 0; p < s.numPoints(); ++p) {
    const Vec3 x = s.position(p);
    cross += (Eigen::Vector3d(x.x, x.y, x.z) - mean) * rest_[std::size_t(p)].transpose();
  }
  Fit f;
  f.leftCols<3>() = cross * inverseGram_;
  f.col(3) = mean;
  return f;
}

double VisibleMotion::cornerDistance(const Fit& a, const Fit& b) const {
  const Fit d = a - b;
  double worst = 0.0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5);
    worst = std::max(worst, (d.leftCols<3>() * corner + d.col(3)).norm());
  }
  return worst;
}

namespace {

struct Attempt {
  bool finished = false;  // false: diverged, failed or over the budget
  std::string why;
  double error = 0.0;  // m
  double wallPerSecond = 0.0;
  long steps = 0;
};

// `kind` at dt (cvode: the sample interval) over the window, the visible motion compared with
// the reference's.
Attempt attempt(const World& w, IntegratorKind kind, double dt, const SolverOptions& options,
                const AtlasSetup& setup, const VisibleMotion& visible,
                const AtlasReference& reference) {
  Simulation sim(w, kind, dt, options);
  const long perSample = std::max(1L, std::lround(setup.interval / dt));
  const long samples = std::lround(setup.time / setup.interval);
  Attempt a;
  double wall = 0.0;
  for (long k = 1; k <= samples; ++k) {
    const auto t0 = Clock::now();
    for (long i = 0; i < perSample; ++i) {
      const StepResult r = sim.step();
      if (!r.ok) {
        a.why = r.message;
        return a;
      }
      // At the sample's end and within it every 16 steps: forward Euler's first sample alone at
      // N = 32 and k = 1e8 (its damped limit c/k) is millions of steps, hours.
      if ((i % 16 == 15 || i + 1 == perSample) && wall + secondsSince(t0) > setup.runBudget) {
        a.why = "over the run budget";
        return a;
      }
    }
    wall += secondsSince(t0);
    a.error = std::max(a.error, visible.cornerDistance(visible.fit(sim.state()),
                                                       reference.samples[std::size_t(k)]));
  }
  a.finished = true;
  a.wallPerSecond = wall / setup.time;
  a.steps = sim.steps();
  return a;
}

// The model's threads set for a scope, and restored after.
class ThreadsFor {
 public:
  explicit ThreadsFor(int threads) : saved_(parallelThreads()) {
    if (threads > 0) setParallelThreads(threads);
  }
  ~ThreadsFor() { setParallelThreads(saved_); }
  ThreadsFor(const ThreadsFor&) = delete;
  ThreadsFor& operator=(const ThreadsFor&) = delete;

 private:
  int saved_;
};

// RK4 at key.dt over the window from w's initial state: the visible motion at every sample,
// read from, resumed from and written to the reference directory when there is one.
std::vector<Fit> referenceFits(const World& w, const TrajectoryKey& key, const AtlasSetup& setup,
                               const VisibleMotion& visible) {
  const std::filesystem::path file =
      setup.referenceDir.empty() ? std::filesystem::path() : setup.referenceDir / key.fileName();
  std::vector<Fit> fits;
  Simulation sim(w, IntegratorKind::RK4, key.dt);
  if (!file.empty()) {
    if (std::optional<StoredTrajectory> stored = readTrajectory(file, key)) {
      fits = std::move(stored->fits);
      if (!stored->resume) return fits;
      std::fprintf(stderr, "jello-scaling: %s: resuming at t = %g s of %g\n", file.c_str(),
                   stored->resume->t, key.time);
      sim.editableState() = *stored->resume;
      sim.stateEdited();
    }
  }
  if (fits.empty()) fits.push_back(visible.fit(sim.state()));
  const long perSample = std::max(1L, std::lround(key.interval / key.dt));
  const long samples = std::lround(key.time / key.interval);
  auto saved = Clock::now();
  for (long k = long(fits.size()); k <= samples; ++k) {
    for (long i = 0; i < perSample; ++i) {
      const StepResult r = sim.step();
      if (!r.ok) throw std::runtime_error("atlas reference: " + r.message);
    }
    fits.push_back(visible.fit(sim.state()));
    if (!file.empty() && k < samples && secondsSince(saved) >= setup.checkpoint) {
      writeTrajectory(file, key, fits, &sim.state());
      saved = Clock::now();
    }
  }
  if (!file.empty()) writeTrajectory(file, key, fits, nullptr);
  return fits;
}

}  // namespace

double atlasMaxFrequency(const World& w, AtlasScene scene) {
  const Model model(w);
  State s = initialState(w);
  const double start = maxAngularFrequency(model, s);
  if (scene == AtlasScene::Free) return start;
  const int n = s.numPoints();
  if (scene == AtlasScene::Falling) {
    // At rest shape, its lowest points 1 mm below the floor (z = -2).
    const double lowest = s.x.tail(n).minCoeff();
    s.x.tail(n).array() += -2.001 - lowest;
    s.v.setZero();
    return std::max(start, maxAngularFrequency(model, s));
  }
  // Slide: at rest shape, its bottom face 1 mm inside the incline; and static friction's damper.
  const Vec3 normal = slideNormal();
  double lowest = INFINITY;
  for (int p = 0; p < n; ++p) lowest = std::min(lowest, dot(normal, s.position(p)) + w.plane->d);
  for (int p = 0; p < n; ++p) State::set(s.x, p, s.position(p) - normal * (lowest + 0.001));
  s.v.setZero();
  const double lambda = 2.0 * w.cubeResolution * w.mass * kGravity;
  const double friction = 2.0 * w.contact.mu * lambda / (w.mass * w.contact.slipSpeed);
  return std::max({start, maxAngularFrequency(model, s), friction});
}

AtlasReference atlasReference(const World& w, double k, AtlasScene scene, const AtlasSetup& setup,
                              AtlasContact contact) {
  const ThreadsFor threads(setup.referenceThreads);
  AtlasReference ref;
  ref.wMax = atlasMaxFrequency(w, scene);
  ref.dt =
      setup.interval /
      std::pow(2.0,
               std::max(0.0, std::ceil(std::log2(setup.interval * ref.wMax / setup.referenceHw))));
  const VisibleMotion visible(w.cubeResolution);
  TrajectoryKey key{
      referenceSceneName(scene, contact), k, w.cubeResolution, ref.dt, setup.interval, setup.time};
  ref.samples = referenceFits(w, key, setup, visible);
  key.dt = 2.0 * ref.dt;
  std::vector<Fit> check = referenceFits(w, key, setup, visible);
  // Halved while RK4 at twice the step is further than setup.referenceCheck of the tolerance
  // from it, each
  // halving's check the run before it: RK4's own error is then about a fifteenth of the check.
  for (int refinement = 0;; ++refinement) {
    ref.check = 0.0;
    for (std::size_t i = 0; i < check.size(); ++i) {
      ref.check = std::max(ref.check, visible.cornerDistance(check[i], ref.samples[i]));
    }
    if (ref.check <= setup.referenceCheck * setup.tolerance ||
        refinement == setup.referenceRefinements) {
      break;
    }
    check = std::move(ref.samples);
    ref.dt /= 2.0;
    key.dt = ref.dt;
    ref.samples = referenceFits(w, key, setup, visible);
  }
  return ref;
}

std::vector<IntegratorKind> atlasIntegrators(bool quick) {
  return quick ? quickAtlasIntegrators() : studyOrder();
}

CsvTable atlasTable() {
  return CsvTable({"k_N_per_m", "n", "w_max_rad_per_s", "integrator", "dt_s", "rtol", "steps",
                   "wall_per_simulated_s", "visible_error_m", "tried", "outcome", "reference_dt_s",
                   "reference_check_m"});
}

void atlasPoint(const World& w, double k, int n, IntegratorKind kind, const AtlasReference& ref,
                const AtlasSetup& setup, CsvTable& table) {
  const double wMax = ref.wMax;
  const VisibleMotion visible(n);
  const double nan = std::nan("");
  // The candidates, largest first: explicit steps from 0.9 of the predicted limit (dividing the
  // sample interval), the others from the interval; cvode's tolerances from 1e-2.
  std::vector<double> steps, rtols;
  if (isAdaptive(kind)) {
    for (int j = 0; j < setup.halvings; ++j) rtols.push_back(std::pow(10.0, -2 - j));
  } else {
    double dt = setup.interval;
    if (isExplicit(kind)) {
      const double limit = 0.9 * predictedThreshold(kind, wMax, w.dElastic / w.kElastic);
      if (limit <= 0.0) {
        table.add({k, long(n), wMax, std::string(integratorName(kind)), nan, nan, 0L, nan, nan, 0L,
                   std::string("never_stable"), ref.dt, ref.check});
        return;
      }
      dt = setup.interval / std::ceil(setup.interval / limit);
    }
    for (int j = 0; j < setup.halvings; ++j, dt /= 2.0) steps.push_back(dt);
  }
  const std::size_t count = isAdaptive(kind) ? rtols.size() : steps.size();
  long tried = 0;
  double lastWall = 0.0, lastError = nan;
  std::string outcome = "not_reached";
  for (std::size_t i = 0; i < count; ++i) {
    // Halving the step doubles the cost: a run that would exceed the budget is not started.
    if (!isAdaptive(kind) && 2.0 * lastWall * setup.time > setup.runBudget) {
      outcome = "budget";
      break;
    }
    SolverOptions options;
    double dt = isAdaptive(kind) ? setup.interval : steps[i];
    if (isAdaptive(kind)) {
      options.cvode.rtol = rtols[i];
      options.cvode.maxStepsPerCall = 100000000;
    }
    const Attempt a = attempt(w, kind, dt, options, setup, visible, ref);
    ++tried;
    if (!a.finished && a.why == "over the run budget") {
      outcome = "budget";
      break;
    }
    lastWall = a.wallPerSecond;
    lastError = a.finished ? a.error : nan;
    if (a.finished && a.error <= setup.tolerance) {
      table.add({k, long(n), wMax, std::string(integratorName(kind)), dt,
                 isAdaptive(kind) ? rtols[i] : nan, a.steps, a.wallPerSecond, a.error, tried,
                 std::string("ok"), ref.dt, ref.check});
      return;
    }
  }
  table.add({k, long(n), wMax, std::string(integratorName(kind)), nan, nan, 0L, nan, lastError,
             tried, outcome, ref.dt, ref.check});
}

}  // namespace jello::experiments
