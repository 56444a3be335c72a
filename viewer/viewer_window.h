// The viewer's window (internal to viewer_app.cpp and viewer_input.cpp): the GLUT callbacks'
// object over the simulation runner(s), the panel and the view state. runViewer (viewer_app.h)
// is the only entry point; display, idle and recording live in viewer_app.cpp, keys and the
// mouse in viewer_input.cpp.
#pragma once

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "viewer/image_writer.h"
#include "viewer/panel.h"
#include "viewer/renderer.h"
#include "viewer/runner_group.h"
#include "viewer/sim_runner.h"
#include "viewer/texture.h"
#include "viewer/video_writer.h"
#include "viewer/viewer_app.h"
#include "viewer/viewer_state.h"

namespace jello::viewer::window {

using Clock = std::chrono::steady_clock;

inline constexpr double kInteractiveFps = 60.0;  // interactive drawing is capped at this rate
inline constexpr double kNoticeSeconds = 4.0, kAlarmSeconds = 8.0, kFadeSeconds = 1.0;

inline std::string format(const char* fmt, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, value);
  return buf;
}

inline double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

// "jello-000.w", "jello-001.w", ...: the first that does not exist.
inline std::optional<std::string> freeName(const char* pattern) {
  for (int i = 0; i < 1000; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, pattern, i);
    if (!std::filesystem::exists(name)) return std::string(name);
  }
  return std::nullopt;
}

inline SimRunner::Options runnerOptions(const ViewerOptions& options) {
  SimRunner::Options r;
  const bool recording = !options.recordDir.empty() || !options.recordVideo.empty();
  r.pacing = recording || options.courseTime ? Pacing::Target : Pacing::RealTime;
  r.speed = options.speed;
  return r;
}

class Viewer {
 public:
  Viewer(const ViewerOptions& options, World world)
      : options_(options), panel_(options.uiScale), viewport_(options.size) {
    if (options.compare.empty()) {
      single_ =
          std::make_unique<SimRunner>(options.source, std::move(world), runnerOptions(options));
    } else {
      group_ = std::make_unique<RunnerGroup>(options.source, world, options.compare,
                                             runnerOptions(options), options.compareSameStep);
    }
    view_.mode = options.wireframe ? DisplayMode::Wireframe : DisplayMode::Shaded;
    view_.showHud = options.hud;
    view_.showField = options.field;
    // --texture FILE (checked by main() already) or builtin; t toggles either.
    const bool file = !options.texture.empty() && options.texture != "builtin";
    texture_ = file ? loadTexture(options.texture) : builtinTexture();
    view_.texture = !options.texture.empty();
    view_.showPanel = options.panel.value_or(!recording());  // recordings: the scene alone
    view_.speed = options.speed;
    frames_.resize(group_ ? group_->size() : 1);
    for (std::size_t i = 0; i < frames_.size(); ++i) frames_[i] = runner(i).frame();
    recordSpan_ =
        recordedFrameSpan(options.speed, options.courseTime, primary().geometry->frameTime);
    recordStart_ = primary().state.t;
    if (options.follow) {  // as key c, framed from the first frame on
      handleKey(view_, 'c');
      view_.camera.follow(primary().state.centroid(), 1.0);
    }
  }

  void display();
  void reshape(int w, int h) {
    viewport_ = {std::max(w, 1), std::max(h, 1)};
    panel_.reshape(w, h);
  }
  void key(unsigned char key);
  void mouse(int button, int state, int x, int y);
  void motion(int x, int y);
  void idle();
  void passiveMotion(int x, int y) {
    panel_.passiveMotion(x, y);
    if (view_.showPanel) glutPostRedisplay();
  }
  void keyUp(unsigned char c, int x, int y) { panel_.keyUp(c, x, y); }
  void special(int key, int x, int y, bool down) {
    panel_.special(key, x, y, down);
    glutPostRedisplay();
  }
  int exitCode() const { return exitCode_; }

 private:
  bool recording() const { return !options_.recordDir.empty() || !options_.recordVideo.empty(); }
  void waitForRecordedFrame();
  void capture(const std::filesystem::path& path);
  // This frame into the recording: frames/NNN.jpg and/or the video. Throws on a failed write.
  void recordFrame();
  void screenshot();
  void notify(std::string message, bool alarm) {
    message_ = std::move(message);
    alarm_ = alarm;
    messageTime_ = Clock::now();
  }
  void takeNotices();
  Overlay overlay(std::size_t pane) const;
  std::string hudLine(std::size_t pane) const;
  Scene scene(std::size_t pane) const;
  void leave(int code) {
    exitCode_ = code;
    glutLeaveMainLoop();
  }
  double pullRadius() const { return pullRadii()[static_cast<std::size_t>(view_.pullRadius)]; }
  std::string restartHint() const;

  ViewerOptions options_;
  // The simulation: one runner, or one per integrator in compare mode.
  SimRunner& runner(std::size_t i = 0) { return single_ ? *single_ : (*group_)[i]; }
  std::size_t runnerCount() const { return group_ ? group_->size() : 1; }
  template <class F>
  void forEachRunner(F f) {
    for (std::size_t i = 0; i < runnerCount(); ++i) f(runner(i));
  }
  void postAll(const std::function<void(ViewerSession&)>& command, bool urgent = false) {
    forEachRunner([&](SimRunner& r) { r.post(command, urgent); });
  }
  double latestTime() const {
    double t = frames_.front().state.t;
    for (const Frame& f : frames_) t = std::max(t, f.state.t);
    return t;
  }
  void drawPanes();
  // Where the scene is drawn: the window, less the panel's column at the right when it shows.
  Viewport sceneViewport() const;

  std::unique_ptr<SimRunner> single_;
  std::unique_ptr<RunnerGroup> group_;
  Panel panel_;
  Image texture_;
  std::vector<Frame> frames_;
  // The first (or only) runner's frame: the heads-up, the panel and picking use it.
  Frame& primary() { return frames_.front(); }
  const Frame& primary() const { return frames_.front(); }
  ViewerState view_;
  Viewport viewport_;
  std::string message_;
  bool alarm_ = false;
  Clock::time_point messageTime_ = Clock::now();
  bool divergenceShown_ = false;
  int exitCode_ = 0;
  bool screenshotPending_ = false;
  int framesDrawn_ = 0;
  double recordSpan_ = 0.0, recordStart_ = 0.0;
  std::unique_ptr<VideoWriter> video_;  // --record-video, started at the first frame
  long drawnPublished_ = -1;

  enum class Drag { None, Rotate, Pan, Push, Pull } drag_ = Drag::None;
  int lastX_ = 0, lastY_ = 0, pressX_ = 0, pressY_ = 0;
  Vec3 anchor_;        // the picked point where the pull began: the drag plane goes through it
  Viewport dragPane_;  // the pane the pull was picked in
  double dragOffsetX_ = 0, dragOffsetY_ = 0;  // its top-left corner in the window
  Vec3 pushAccel_;

  Clock::time_point started_ = Clock::now(), rateWindow_ = Clock::now(), lastDraw_ = Clock::now();
  int windowFrames_ = 0;
  double fps_ = 0.0;
};

}  // namespace jello::viewer::window
