#include "viewer/viewer_session.h"

#include "viewer/interaction.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {

ViewerSession::ViewerSession(SceneSource source, World world) : source_(std::move(source)) {
  build(std::move(world));
}

void ViewerSession::build(World world) {
  sim_ = std::make_unique<Simulation>(std::move(world), source_.integrator, source_.dt);
  lattice_ = Lattice{sim_->world().cubeResolution};
  mesh_ = surfaceMesh(lattice_);
  springs_ = viewer::surfaceSprings(sim_->model().springs().springs(), lattice_);
  arrows_ = fieldArrows(sim_->world().field);
  dt0_ = sim_->dt();
  frameTime_ = sim_->world().stepsPerFrame * sim_->world().dt;
  drag_ = Drag::None;
}

std::optional<std::string> ViewerSession::reload() {
  World world;
  try {
    world = readWorld(source_.world, source_.limits);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  build(std::move(world));
  return std::nullopt;
}

std::optional<std::string> ViewerSession::advance(double frameTime) {
  if (sim_->divergence()) return sim_->divergence()->describe();
  applyUserForce();
  const int steps = stepsPerFrame(frameTime, sim_->dt());
  for (int i = 0; i < steps; ++i) {
    if (StepResult r = sim_->step(); !r.ok) return r.message;
  }
  return std::nullopt;
}

void ViewerSession::applyUserForce() {
  const World& w = sim_->world();
  if (drag_ == Drag::Push) {
    sim_->setUserForce(pushForce(sim_->model().numPoints(), w.mass, accel_));
  } else if (drag_ == Drag::Pull) {
    // Stiff enough to move a point against its springs; the lattice's own k sets the scale.
    const double k = w.kElastic > 0.0 ? w.kElastic : 100.0;
    sim_->setUserForce(pullForce(lattice_, sim_->state(), picked_, target_, radius_, k));
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
