#include "experiments/studies/atlas_scene.h"

#include <algorithm>
#include <cmath>

#include "experiments/studies/stability_analysis.h"
#include "src/base/closed_set.h"
#include "src/effects/obstacle.h"
#include "src/model.h"
#include "src/world/scene_builder.h"

namespace jello::experiments {

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

}  // namespace

std::optional<AtlasScene> parseAtlasScene(const std::string& name) {
  return closed_set::parse(kScenes, name);
}

std::string sceneName(AtlasScene scene) {
  return std::string(closed_set::row(kScenes, scene).name);
}

std::vector<std::string> sceneNames() {
  return closed_set::nameList(kScenes);
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

namespace {

// The contact settings: name, kCollision as a multiple of k (0: the course's 400 N/m), model.
struct ContactRow {
  AtlasContact kind;
  std::string_view name;
  double timesK;
  ContactModel model;
};
constexpr ContactRow kContacts[] = {
    {AtlasContact::Soft, "soft", 0.0, ContactModel::Penalty},
    {AtlasContact::AsStiff, "k", 1.0, ContactModel::Penalty},
    {AtlasContact::Stiffer, "20k", 20.0, ContactModel::Penalty},
    {AtlasContact::Barrier, "barrier", 1.0, ContactModel::Barrier},
};

}  // namespace

std::optional<AtlasContact> parseAtlasContact(const std::string& name) {
  return closed_set::parse(kContacts, name);
}

std::string contactName(AtlasContact contact) {
  return std::string(closed_set::row(kContacts, contact).name);
}

std::vector<std::string> contactNames() {
  return closed_set::nameList(kContacts);
}

double contactStiffness(AtlasContact contact, double k) {
  const double times = closed_set::row(kContacts, contact).timesK;
  return times > 0.0 ? times * k : 400.0;  // the course's kCollision
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
  if (closed_set::row(kContacts, contact).model == ContactModel::Barrier) {
    spec.contact.model = ContactModel::Barrier;
    spec.contact.dhat = kDefaultBarrierDistance;
    spec.contact.kappa = spec.kCollision;
  }
  if (scene == AtlasScene::Slide) return slideScene(spec);
  World w = buildWorld(spec);
  // Centred in the box: falling, 1.5 m above the floor (z = -2), reached after about 0.55 s;
  // free, 1 s of drift moves it 0.5 m, its corners (0.87 m from the centre) stay 0.6 m from
  // the walls.
  for (Vec3& p : w.positions) p += Vec3{-0.5, -0.5, -0.5};
  return w;
}

namespace {

// N: what a bottom point of the cube at rest carries at most, bounded by twice the weight of a
// column of N points.
double columnLoad(const World& w) {
  return 2.0 * w.cubeResolution * defaultFieldStrength(FieldPreset::Gravity, w.mass);
}

// m: the bottom face's signed distance from the solid where w_max is taken: 1 mm inside for the
// penalty models (every bottom point on a contact spring); for the barrier, outside, where its
// force carries columnLoad (bisection: the force falls from +inf at 0 to 0 at dhat).
double restingDistance(const World& w) {
  if (w.contact.model != ContactModel::Barrier) return -0.001;
  const double load = columnLoad(w);
  double lo = 0.0, hi = w.contact.dhat;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double mid = 0.5 * (lo + hi);
    (barrierContactLaw(-mid, w.contact.kappa, w.contact.dhat).force > load ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double atlasMaxFrequency(const World& w, AtlasScene scene) {
  const Model model(w);
  State s = initialState(w);
  const double start = maxAngularFrequency(model, s);
  if (scene == AtlasScene::Free) return start;
  const int n = s.numPoints();
  const double distance = restingDistance(w);
  if (scene == AtlasScene::Falling) {
    // At rest shape, its lowest points `distance` above the floor (z = -2).
    const double lowest = s.x.tail(n).minCoeff();
    s.x.tail(n).array() += -2.0 + distance - lowest;
    s.v.setZero();
    return std::max(start, maxAngularFrequency(model, s));
  }
  // Slide: at rest shape, its bottom face `distance` from the incline; and static friction's
  // damper.
  const Vec3 normal = slideNormal();
  double lowest = INFINITY;
  for (int p = 0; p < n; ++p) lowest = std::min(lowest, dot(normal, s.position(p)) + w.plane->d);
  for (int p = 0; p < n; ++p) State::set(s.x, p, s.position(p) + normal * (distance - lowest));
  s.v.setZero();
  const double friction = 2.0 * w.contact.mu * columnLoad(w) / (w.mass * w.contact.slipSpeed);
  return std::max({start, maxAngularFrequency(model, s), friction});
}

}  // namespace jello::experiments
