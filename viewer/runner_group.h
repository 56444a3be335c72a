// Integrators side by side: one SimRunner per integrator on the same world, stepped to one shared
// simulated time. The group's target follows the wall clock times the speed, but moves on only
// when every running member has reached it, so all panes always show the same instant; a member
// that diverged stops and no longer holds the others back.
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "viewer/sim_runner.h"

namespace jello::viewer {

// The step a compare pane takes by default (--compare-dt auto): an explicit method at 0.9 of
// its predicted stability limit (solvers/system/modes.h) on the fastest mode `wMax` with damping
// ratio r = c/k, at most one frame (1/60 s); every other method one frame.
inline constexpr double kCompareFrame = 1.0 / 60.0;
double compareStep(IntegratorKind kind, double wMax, double dampingRatio);
// The world's fastest mode at its start for compareStep: the springs' (Spectra), with a penalty
// contact's kCollision/m added, as the cube will touch something; nothing when it cannot be
// computed.
std::optional<double> compareWMax(const World& world);

class RunnerGroup {
 public:
  // Each runner in Target pacing on its own thread, `world` under each integrator, each at its
  // compareStep unless `sameStep` (or source.dt) gives them all one.
  RunnerGroup(const SceneSource& source, const World& world,
              const std::vector<IntegratorKind>& integrators, SimRunner::Options options,
              bool sameStep = true);

  std::size_t size() const { return runners_.size(); }
  SimRunner& operator[](std::size_t i) { return *runners_[i]; }
  const SimRunner& operator[](std::size_t i) const { return *runners_[i]; }

  // Real-time pacing, called once per displayed frame with the wall clock (s): when all have
  // reached the target, it moves on by speed times the wall time since the last move (at most
  // kMaxBacklog of wall time). Paused, nothing moves.
  void tick(double wall);
  void setSpeed(double speed) { speed_ = speed; }
  void setPaused(bool paused);
  // One shared step of `span` simulated seconds (recording, `.` while paused, course time).
  void advanceBy(double span);
  double target() const { return target_; }
  // The target every running member has reached: the instant all panes show
  // (SimRunner::frameAt), while the faster ones may already be at target().
  double shown() const { return shown_; }
  // Simulated seconds per wall second of the shown instant over the last half second, and the
  // wall seconds that covers (0 at the start and after a reload): the slowest member's pace.
  double rate() const;
  double rateSpan() const;
  // True when every member that has not diverged shows the target time (to one step).
  bool allReached() const;
  // Sets the shared target (recording; after a reload, time starts over).
  void setTarget(double t);

 private:
  void setTargetAll();

  std::vector<std::unique_ptr<SimRunner>> runners_;
  double speed_ = 1.0;
  bool paused_ = false;
  double target_ = 0.0;
  double shown_ = 0.0;
  double lastWall_ = -1.0;
  std::deque<std::pair<double, double>> shownAt_;  // (wall, shown) when shown moved
};

}  // namespace jello::viewer
