#include "viewer/runner_group.h"

#include <algorithm>

namespace jello::viewer {

RunnerGroup::RunnerGroup(const SceneSource& source, const World& world,
                         const std::vector<IntegratorKind>& integrators,
                         SimRunner::Options options) {
  options.pacing = Pacing::Target;
  speed_ = options.speed;
  paused_ = options.paused;
  options.paused = false;  // the group's target holds them
  for (IntegratorKind kind : integrators) {
    SceneSource s = source;
    s.integrator = kind;
    runners_.push_back(std::make_unique<SimRunner>(s, world, options));
  }
  target_ = runners_.empty() ? 0.0 : runners_.front()->frame().state.t;
}

bool RunnerGroup::allReached() const {
  for (const auto& r : runners_) {
    const Frame f = r->frame();
    if (!f.divergence && f.state.t < target_ - 1e-12) return false;
  }
  return true;
}

void RunnerGroup::setTargetAll() {
  for (auto& r : runners_) r->setTarget(target_);
}

void RunnerGroup::tick(double wall) {
  if (paused_) {
    lastWall_ = -1.0;
    return;
  }
  if (lastWall_ < 0.0) lastWall_ = wall;
  if (!allReached()) return;
  const double elapsed = std::min(wall - lastWall_, kMaxBacklog);
  lastWall_ = wall;
  if (elapsed <= 0.0) return;
  target_ += speed_ * elapsed;
  setTargetAll();
}

void RunnerGroup::setPaused(bool paused) {
  paused_ = paused;
  lastWall_ = -1.0;
}

void RunnerGroup::advanceBy(double span) {
  target_ += span;
  setTargetAll();
}

void RunnerGroup::setTarget(double t) {
  target_ = t;
  lastWall_ = -1.0;
  setTargetAll();
}

}  // namespace jello::viewer
