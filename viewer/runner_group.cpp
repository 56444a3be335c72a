#include "viewer/runner_group.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include "solvers/system/modes.h"
#include "src/model.h"
#include "src/state.h"

namespace jello::viewer {

double compareStep(IntegratorKind kind, double wMax, double dampingRatio) {
  const double limit = predictedThreshold(kind, wMax, dampingRatio);
  return std::isfinite(limit) && limit > 0.0 ? std::min(0.9 * limit, kCompareFrame) : kCompareFrame;
}

std::optional<double> compareWMax(const World& world) {
  try {
    const double springs = maxAngularFrequency(Model(world), initialState(world));
    return std::sqrt(springs * springs + world.kCollision / world.mass);
  } catch (const std::exception&) {
    return std::nullopt;  // the world's own step for every pane
  }
}

RunnerGroup::RunnerGroup(const SceneSource& source, const World& world,
                         const std::vector<IntegratorKind>& integrators, SimRunner::Options options,
                         bool sameStep) {
  options.pacing = Pacing::Target;
  speed_ = options.speed;
  paused_ = options.paused;
  options.paused = false;  // the group's target holds them
  const std::optional<double> wMax = sameStep || source.dt ? std::nullopt : compareWMax(world);
  const double dampingRatio = world.kElastic > 0.0 ? world.dElastic / world.kElastic : 0.0;
  for (IntegratorKind kind : integrators) {
    SceneSource s = source;
    s.integrator = kind;
    if (wMax) s.dt = compareStep(kind, *wMax, dampingRatio);
    runners_.push_back(std::make_unique<SimRunner>(s, world, options));
  }
  target_ = shown_ = runners_.empty() ? 0.0 : runners_.front()->frame().state.t;
}

double RunnerGroup::rate() const {
  if (shownAt_.size() < 2) return 0.0;
  const double span = shownAt_.back().first - shownAt_.front().first;
  return span > 0.0 ? (shownAt_.back().second - shownAt_.front().second) / span : 0.0;
}

double RunnerGroup::rateSpan() const {
  return shownAt_.size() < 2 ? 0.0 : shownAt_.back().first - shownAt_.front().first;
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
  shown_ = target_;
  shownAt_.emplace_back(wall, shown_);
  while (shownAt_.size() > 2 && shownAt_[1].first <= wall - 0.5) shownAt_.pop_front();
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
  if (allReached()) shown_ = target_;
  target_ += span;
  setTargetAll();
}

void RunnerGroup::setTarget(double t) {
  if (t < shown_) shownAt_.clear();  // a reload: time starts over
  target_ = shown_ = t;
  lastWall_ = -1.0;
  setTargetAll();
}

}  // namespace jello::viewer
