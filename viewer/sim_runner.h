// The simulation thread behind the viewer, free of GL. A SimRunner owns a ViewerSession and steps
// it on its own thread; the render thread only posts commands (applied between steps) and copies
// the latest published Frame, so drawing, keys and the mouse never wait for a step, however
// long one takes. Commands that change the scene (reload, integrator, time step, quit) also cut
// a long step short (src/base/interrupt.h): the step is retried afterwards from its start.
//
// Pacing: by default simulated time follows the wall clock times a playback speed. When the
// simulation cannot keep up, it runs as fast as it can and at most kMaxBacklog wall seconds of
// simulated time are owed: the rest is dropped, and the frame says it is lagging with the rate it
// actually reaches. In Target pacing nothing advances by itself: the caller sets the simulated
// time to reach (course time: n*dt per displayed frame; recording: 1/15 s per frame).
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "solvers/integrator.h"
#include "solvers/solver_options.h"
#include "viewer/viewer_session.h"

namespace jello::viewer {

inline constexpr double kMaxBacklog = 0.25;  // wall seconds of simulated time owed at most

// The energy the heads-up and the panel show, J: the field's, the user force's and friction's
// share is minus the work they did since the start (friction's: what it dissipated), so
// `total` changes only by damping.
struct EnergyReport {
  double kinetic = 0.0, spring = 0.0, contact = 0.0, field = 0.0, user = 0.0, friction = 0.0;
  double total() const { return kinetic + spring + contact + field + user + friction; }
};
EnergyReport energyReport(const Simulation& sim);
// Friction's force on each point that has one, as arrows from the point along the force (the
// strongest `longest` metres long); none without friction or contact.
std::vector<Arrow> frictionArrows(const Simulation& sim, double longest = 0.25);

// One published picture of the simulation.
struct Frame {
  std::shared_ptr<const SceneGeometry> geometry;
  long generation = 0;  // bumped when the geometry is replaced
  State state;          // always a sane state
  IntegratorKind integrator = IntegratorKind::RK4;
  double dt = 0.0;
  long steps = 0;
  EnergyReport energy;
  Vec3 angularMomentum;
  std::vector<Statistic> solver;  // the integrator's counters
  std::vector<Arrow> friction;    // friction's forces (frictionArrows), drawn with the field's
  SolverOptions solverOptions;    // the integrator's settings
  std::optional<std::string> divergence;
  std::optional<std::pair<int, Vec3>> pull;  // picked point and target while pulling
  double speed = 1.0;
  bool paused = false;
  double simRate = 0.0;   // simulated seconds per wall second over the last half second
  double rateSpan = 0.0;  // wall seconds that rate covers (0 right after a reload)
  bool lagging = false;   // simulated time was dropped in the last second
};

struct Notice {
  std::string text;
  bool alarm = false;
};

enum class Pacing { RealTime, Target };

class SimRunner {
 public:
  using WallClock = std::function<double()>;  // seconds, monotonic

  struct Options {
    Pacing pacing = Pacing::RealTime;
    double speed = 1.0;
    bool paused = false;
    WallClock clock;                   // empty: std::chrono::steady_clock
    std::function<void()> beforeStep;  // tests: a slow step
  };

  SimRunner(SceneSource source, World world, Options options);
  ~SimRunner();  // stops the thread, cutting a long step short
  SimRunner(const SimRunner&) = delete;
  SimRunner& operator=(const SimRunner&) = delete;

  // The latest published frame (a copy; never waits for a step).
  Frame frame() const;
  // Target pacing: the frame published when the simulation reached `target` (the last few
  // targets are kept), or nothing. Compare mode draws every pane at the target all reached.
  std::optional<Frame> frameAt(double target) const;
  // Messages from the simulation thread (divergence, reload results) since the last call.
  std::vector<Notice> takeNotices();
  // Adds a message; commands call it from the simulation thread. A command that throws adds
  // its exception's text as an alarm.
  void notify(Notice notice);
  // How many frames have been published: a renderer with nothing new to draw can idle.
  long published() const;

  // Runs `command` on the simulation thread between steps. `urgent` cuts a running step short.
  void post(std::function<void(ViewerSession&)> command, bool urgent = false);
  void setPaused(bool paused);
  void setSpeed(double speed);
  // Target pacing: the simulated time to reach; advanceTarget adds `span` to it, keeping it
  // at most `span` ahead of the simulation (a slow simulation is not made to catch up).
  void setTarget(double t);
  void advanceTarget(double span);
  // One displayed frame's worth (n*dt) of simulated time, also while paused.
  void stepFrame();
  // Blocks until the simulation reaches simulated time `t`, diverges or `timeout` (wall s)
  // passes; true when it reached t. For recording and tests.
  bool waitFor(double t, double timeout);
  // Blocks until the posted commands have run and a frame after them is published.
  void sync();

 private:
  void loop();
  void publish(std::unique_lock<std::mutex>& lock);
  double now() const;
  double targetLocked(double t, double wall);
  void rebaseLocked(double wall);

  ViewerSession session_;
  Options options_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;     // the simulation thread: a command, a new target, quit
  std::condition_variable reached_;  // waiters: a frame was published
  std::vector<std::function<void(ViewerSession&)>> commands_;
  std::vector<Notice> notices_;
  Frame latest_;
  std::shared_ptr<const SceneGeometry> geometry_;
  long generation_ = 0;
  long commandsPosted_ = 0, commandsDone_ = 0, published_ = 0;
  bool quit_ = false, stepping_ = false;
  bool paused_ = false;
  double speed_ = 1.0;
  // Real time: simulated time baseSim_ at wall time baseWall_; Target pacing: target_.
  double baseSim_ = 0.0, baseWall_ = 0.0, target_ = 0.0;
  double frameTarget_ = -1e300;                         // paused: the time `.` asked for
  double lastDrop_ = -1e300;                            // wall time simulated time was last dropped
  std::deque<std::pair<double, double>> rate_;          // (wall, simulated) at publishes
  std::deque<std::pair<double, Frame>> reachedFrames_;  // Target pacing: (target, its frame)
  double lastPublish_ = -1e300;

  std::thread thread_;
};

}  // namespace jello::viewer
