#include "viewer/sim_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>

#include "src/base/interrupt.h"

namespace jello::viewer {

namespace {

// Frames are published at most this often while stepping (wall seconds), and always when the
// simulation reaches its target.
constexpr double kPublishInterval = 1.0 / 120.0;
constexpr double kRateWindow = 0.5;  // wall seconds the simulated-time rate is measured over

double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

EnergyReport energyReport(const Simulation& sim) {
  const Energy e = sim.model().energy(sim.state());
  EnergyReport r;
  r.kinetic = e.kinetic;
  r.spring = e.spring;
  r.contact = e.contact;
  r.field = 0.0 - sim.fieldWork();  // 0 - 0 is +0: no "-0" in the heads-up
  r.user = 0.0 - sim.userForceWork();
  r.friction = 0.0 - sim.frictionWork();
  return r;
}

std::vector<Arrow> frictionArrows(const Simulation& sim, double longest) {
  std::vector<Arrow> arrows;
  if (!sim.model().hasFriction()) return arrows;
  const State& s = sim.state();
  Eigen::VectorXd f;
  sim.model().frictionForces(s.x.data(), s.v.data(), f);
  const int n = s.numPoints();
  double strongest = 0.0;
  for (int p = 0; p < n; ++p) strongest = std::max(strongest, norm(State::at(f, p)));
  if (!(strongest > 0.0) || !std::isfinite(strongest)) return arrows;
  for (int p = 0; p < n; ++p) {
    const Vec3 force = State::at(f, p);
    const double magnitude = norm(force);
    if (magnitude == 0.0) continue;
    const Vec3 tail = s.position(p);
    arrows.push_back(
        {tail, tail + force * (longest / strongest), magnitude / strongest, magnitude});
  }
  return arrows;
}

SimRunner::SimRunner(SceneSource source, World world, Options options)
    : session_(std::move(source), std::move(world)), options_(std::move(options)) {
  if (!options_.clock) options_.clock = steadySeconds;
  paused_ = options_.paused;
  speed_ = options_.speed;
  geometry_ = session_.geometry();
  target_ = baseSim_ = session_.simulation().state().t;
  baseWall_ = now();
  {
    std::unique_lock lock(mutex_);
    publish(lock);
  }
  thread_ = std::thread([this] { loop(); });
}

SimRunner::~SimRunner() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
    if (stepping_) requestInterrupt(SIGTERM);
  }
  wake_.notify_all();
  thread_.join();
  clearInterrupt();
}

double SimRunner::now() const {
  return options_.clock();
}

Frame SimRunner::frame() const {
  std::lock_guard lock(mutex_);
  return latest_;
}

std::optional<Frame> SimRunner::frameAt(double target) const {
  std::lock_guard lock(mutex_);
  for (auto at = reachedFrames_.rbegin(); at != reachedFrames_.rend(); ++at) {
    if (at->first == target) return at->second;
  }
  return std::nullopt;
}

std::vector<Notice> SimRunner::takeNotices() {
  std::lock_guard lock(mutex_);
  return std::exchange(notices_, {});
}

void SimRunner::notify(Notice notice) {
  std::lock_guard lock(mutex_);
  notices_.push_back(std::move(notice));
}

long SimRunner::published() const {
  std::lock_guard lock(mutex_);
  return published_;
}

void SimRunner::post(std::function<void(ViewerSession&)> command, bool urgent) {
  {
    std::lock_guard lock(mutex_);
    commands_.push_back(std::move(command));
    ++commandsPosted_;
    if (urgent && stepping_) requestInterrupt(SIGTERM);
  }
  wake_.notify_all();
}

void SimRunner::setPaused(bool paused) {
  {
    std::lock_guard lock(mutex_);
    if (paused_ == paused) return;
    paused_ = paused;
    rebaseLocked(now());
  }
  wake_.notify_all();
}

void SimRunner::setSpeed(double speed) {
  {
    std::lock_guard lock(mutex_);
    rebaseLocked(now());
    speed_ = speed;
  }
  wake_.notify_all();
}

void SimRunner::setTarget(double t) {
  {
    std::lock_guard lock(mutex_);
    target_ = t;
  }
  wake_.notify_all();
}

void SimRunner::advanceTarget(double span) {
  {
    std::lock_guard lock(mutex_);
    target_ = std::min(target_, latest_.state.t + span) + span;
  }
  wake_.notify_all();
}

void SimRunner::stepFrame() {
  {
    std::lock_guard lock(mutex_);
    frameTarget_ = std::max(frameTarget_, latest_.state.t) + geometry_->frameTime;
  }
  wake_.notify_all();
}

bool SimRunner::waitFor(double t, double timeout) {
  std::unique_lock lock(mutex_);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::max(0.0, timeout));
  reached_.wait_until(lock, deadline,
                      [&] { return latest_.state.t >= t - 1e-12 || latest_.divergence; });
  return latest_.state.t >= t - 1e-12;
}

void SimRunner::sync() {
  std::unique_lock lock(mutex_);
  const long posted = commandsPosted_;
  wake_.notify_all();
  reached_.wait(lock, [&] { return commandsDone_ >= posted && !stepping_; });
}

void SimRunner::rebaseLocked(double wall) {
  baseSim_ = latest_.state.t;
  baseWall_ = wall;
}

double SimRunner::targetLocked(double t, double wall) {
  if (options_.pacing == Pacing::Target) return target_;
  double target = baseSim_ + speed_ * (wall - baseWall_);
  if (target - t > speed_ * kMaxBacklog) {
    // Behind by more than the backlog allows: the excess is dropped, not caught up later.
    baseSim_ = t + speed_ * kMaxBacklog;
    baseWall_ = wall;
    target = baseSim_;
    lastDrop_ = wall;
  }
  return target;
}

void SimRunner::publish(std::unique_lock<std::mutex>& lock) {
  // Computed without the lock: only this thread (or the constructor) touches the session.
  lock.unlock();
  const Simulation& sim = session_.simulation();
  Frame f;
  f.state = sim.state();
  f.integrator = sim.integratorKind();
  f.dt = sim.dt();
  f.steps = sim.steps();
  f.energy = energyReport(sim);
  f.angularMomentum = sim.model().angularMomentum(sim.state());
  f.solver = sim.integrator().statistics();
  f.friction = frictionArrows(sim);
  f.solverOptions = sim.solverOptions();
  if (sim.divergence()) f.divergence = sim.divergence()->describe();
  f.pull = session_.pulling();
  const double wall = now();
  lock.lock();
  if (session_.geometry() != geometry_) {
    geometry_ = session_.geometry();
    ++generation_;
  }
  f.geometry = geometry_;
  f.generation = generation_;
  f.speed = speed_;
  f.paused = paused_;
  // Time that went back (a reload, an edit of the state) starts the measure over: measured
  // across it, the rate read "-60.8 s per wall second".
  if (!rate_.empty() && (f.state.t < rate_.back().second || f.generation != latest_.generation)) {
    rate_.clear();
    reachedFrames_.clear();
  }
  rate_.emplace_back(wall, f.state.t);
  while (rate_.size() > 2 && rate_[1].first <= wall - kRateWindow) rate_.pop_front();
  const double span = wall - rate_.front().first;
  f.rateSpan = span;
  f.simRate = span > 0.0 ? (f.state.t - rate_.front().second) / span : 0.0;
  f.lagging = wall - lastDrop_ < 1.0;
  latest_ = std::move(f);
  if (options_.pacing == Pacing::Target && latest_.state.t >= target_ - 1e-12) {
    // Reached: kept under its target (replaced while it stays, a pull edits the state).
    if (!reachedFrames_.empty() && reachedFrames_.back().first == target_) {
      reachedFrames_.back().second = latest_;
    } else {
      reachedFrames_.emplace_back(target_, latest_);
      if (reachedFrames_.size() > 4) reachedFrames_.pop_front();
    }
  }
  lastPublish_ = wall;
  ++published_;
  reached_.notify_all();
}

void SimRunner::loop() {
  std::unique_lock lock(mutex_);
  while (!quit_) {
    if (!commands_.empty()) {
      std::vector<std::function<void(ViewerSession&)>> commands = std::exchange(commands_, {});
      lock.unlock();
      clearInterrupt();
      for (auto& command : commands) {
        try {
          command(session_);
        } catch (const std::exception& e) {
          notify({e.what(), true});
        }
      }
      lock.lock();
      const double before = latest_.state.t;
      publish(lock);
      // Done only once their frame is out (publish unlocks while it builds the frame): sync()
      // returning in between handed out the frame from before the commands.
      commandsDone_ += static_cast<long>(commands.size());
      reached_.notify_all();
      if (latest_.state.t != before) {  // a reload: time starts over
        rebaseLocked(now());
        target_ = frameTarget_ = latest_.state.t;
      }
      continue;
    }
    const Simulation& sim = session_.simulation();
    const double t = sim.state().t, wall = now();
    const double target = paused_ ? frameTarget_ : targetLocked(t, wall);
    const bool run = !sim.divergence() && t < target;
    if (!run) {
      if (latest_.state.t != t || wall - lastPublish_ > 0.25) publish(lock);
      // Real time: sleep until the target passes t (at most 20 ms); a command wakes us early.
      double wait = 0.05;
      if (options_.pacing == Pacing::RealTime && !paused_ && !sim.divergence() && speed_ > 0.0)
        wait = std::clamp((t - target) / speed_, 0.001, 0.02);
      wake_.wait_for(lock, std::chrono::duration<double>(wait));
      continue;
    }
    stepping_ = true;
    lock.unlock();
    if (options_.beforeStep) options_.beforeStep();
    const StepResult result = session_.step();
    if (result.interrupted) clearInterrupt();
    lock.lock();
    stepping_ = false;
    if (!result.ok && !result.interrupted) {
      notices_.push_back({result.message, true});
      publish(lock);
      continue;
    }
    const double after = session_.simulation().state().t;
    const double goal = paused_ ? frameTarget_ : targetLocked(after, now());
    if (now() - lastPublish_ >= kPublishInterval || after >= goal) publish(lock);
  }
}

}  // namespace jello::viewer
