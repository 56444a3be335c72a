#include "viewer/viewer_session.h"

#include "src/model.h"
#include "src/world/world_writer.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {

namespace {

std::shared_ptr<const SceneGeometry> makeGeometry(const Simulation& sim) {
  auto g = std::make_shared<SceneGeometry>();
  g->lattice = Lattice{sim.world().cubeResolution};
  g->mesh = surfaceMesh(g->lattice);
  g->springs = surfaceSprings(sim.model().springs().springs(), g->lattice);
  g->arrows = fieldArrows(sim.world().field);
  g->frameTime = sim.world().stepsPerFrame * sim.world().dt;
  g->world = sim.world();
  g->world.field = {};
  g->world.positions.clear();
  g->world.velocities.clear();
  return g;
}

}  // namespace

ViewerSession::ViewerSession(SceneSource source, World world) : source_(std::move(source)) {
  build(std::move(world));
}

void ViewerSession::build(World world) {
  sim_ = std::make_unique<Simulation>(std::move(world), source_.integrator, source_.dt);
  geometry_ = makeGeometry(*sim_);
  dt0_ = sim_->dt();
  drag_ = Drag::None;
}

std::optional<std::string> ViewerSession::reload() {
  World world;
  try {
    world = readWorld(source_.world, source_.limits);
    checkStart(world, source_.world.string());
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  build(std::move(world));
  return std::nullopt;
}

void ViewerSession::editWorld(const std::function<void(World&)>& edit) {
  World world = sim_->currentWorld();
  edit(world);
  const IntegratorKind kind = sim_->integratorKind();
  const SolverOptions options = sim_->solverOptions();
  const double dt = sim_->dt(), t = sim_->state().t;
  sim_ = std::make_unique<Simulation>(std::move(world), kind, dt, options);
  sim_->editableState().t = t;
  sim_->stateEdited();
  geometry_ = makeGeometry(*sim_);
  if (drag_ == Drag::None) sim_->clearUserForce();
}

void ViewerSession::save(const std::filesystem::path& path) const {
  writeWorld(sim_->currentWorld(), path);
}

StepResult ViewerSession::step() {
  applyUserForce();
  return sim_->step();
}

std::optional<std::string> ViewerSession::advance(double frameTime) {
  if (sim_->divergence()) return sim_->divergence()->describe();
  const int steps = stepsPerFrame(frameTime, sim_->dt());
  for (int i = 0; i < steps; ++i) {
    if (StepResult r = step(); !r.ok) return r.message;
  }
  return std::nullopt;
}

void ViewerSession::applyUserForce() {
  const World& w = sim_->world();
  if (drag_ == Drag::Push) {
    sim_->setUserForce(pushForce(sim_->model().numPoints(), w.mass, accel_));
  } else if (drag_ == Drag::Pull) {
    const PullSpring spring = pullSpring(sim_->model().numPoints(), w.mass, w.kElastic, pullScale_);
    sim_->setUserForce(pullForce(lattice(), sim_->state(), picked_, target_, radius_, spring));
  }
}

void ViewerSession::push(const Vec3& accel) {
  drag_ = Drag::Push;
  accel_ = accel;
}

void ViewerSession::pull(int picked, const Vec3& target, double radius) {
  drag_ = Drag::Pull;
  picked_ = picked;
  target_ = target;
  radius_ = radius;
}

void ViewerSession::release() {
  drag_ = Drag::None;
  sim_->clearUserForce();
}

std::optional<std::pair<int, Vec3>> ViewerSession::pulling() const {
  if (drag_ != Drag::Pull) return std::nullopt;
  return std::pair(picked_, target_);
}

}  // namespace jello::viewer
