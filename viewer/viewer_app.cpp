#include "viewer/viewer_app.h"

#include <GL/freeglut.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "viewer/image_writer.h"
#include "viewer/interaction.h"
#include "viewer/renderer.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {
namespace {

using Clock = std::chrono::steady_clock;

std::string format(const char* fmt, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, value);
  return buf;
}

double seconds(Clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

class Viewer {
 public:
  Viewer(const ViewerOptions& options, World world)
      : options_(options), session_(options.source, std::move(world)), viewport_(options.size) {
    view_.mode = options.wireframe ? DisplayMode::Wireframe : DisplayMode::Shaded;
    view_.showHud = options.hud;
  }

  void display();
  void reshape(int w, int h) { viewport_ = {std::max(w, 1), std::max(h, 1)}; }
  void key(unsigned char key);
  void mouse(int button, int state, int x, int y);
  void motion(int x, int y);
  int exitCode() const { return exitCode_; }

 private:
  void advance();
  void capture(const std::filesystem::path& path);
  void screenshot();
  void notify(std::string message, bool alarm) {
    overlay_.message = std::move(message);
    overlay_.alarm = alarm;
  }
  std::string hudLine() const;
  void leave(int code) {
    exitCode_ = code;
    glutLeaveMainLoop();
  }
  double pullRadius() const { return pullRadii()[static_cast<std::size_t>(view_.pullRadius)]; }

  ViewerOptions options_;
  ViewerSession session_;
  ViewerState view_;
  Viewport viewport_;
  Overlay overlay_;
  int exitCode_ = 0;
  bool screenshotPending_ = false;
  int framesDrawn_ = 0;

  enum class Drag { None, Rotate, Push, Pull } drag_ = Drag::None;
  int lastX_ = 0, lastY_ = 0, pressX_ = 0, pressY_ = 0;
  Vec3 anchor_;  // the picked point where the pull began: the drag plane goes through it

  // Rates over the last half second.
  Clock::time_point started_ = Clock::now(), rateWindow_ = Clock::now(),
                    lastAdvance_ = Clock::now();
  int windowFrames_ = 0;
  double windowSimTime_ = 0.0, fps_ = 0.0, realTimeFactor_ = 0.0;
};

std::string Viewer::hudLine() const {
  const Simulation& sim = session_.simulation();
  std::ostringstream os;
  os << integratorName(sim.integratorKind()) << "  dt " << format("%.3g", sim.dt()) << " s  t "
     << format("%.3f", sim.state().t) << " s  " << format("%.0f", fps_) << " fps  "
     << format("%.3g", realTimeFactor_) << "x real time  E "
     << format("%.4g", sim.model().energy(sim.state()).total()) << " J";
  if (view_.paused || view_.pullMode || drag_ == Drag::Pull) os << '\n';
  if (view_.paused) os << "[paused]  ";
  if (view_.pullMode || drag_ == Drag::Pull) {
    const double r = pullRadius();
    os << "pull radius " << (std::isinf(r) ? std::string("whole cube") : format("%.2g m", r));
  }
  return os.str();
}

void Viewer::advance() {
  const Clock::time_point now = Clock::now();
  double frameTime = session_.frameTime();
  if (options_.realTime) frameTime = std::min(0.1, seconds(now - lastAdvance_));
  lastAdvance_ = now;
  const double t0 = session_.simulation().state().t;
  const bool divergedBefore = session_.simulation().divergence().has_value();
  if (std::optional<std::string> failure = session_.advance(frameTime)) {
    view_.paused = true;
    notify(*failure + " - press r to reload", true);
    if (!divergedBefore) std::cerr << "jello: " << *failure << '\n';
  }
  windowSimTime_ += session_.simulation().state().t - t0;
}

void Viewer::capture(const std::filesystem::path& path) {
  writeJpeg(path, imageFromBottomUp(viewport_.width, viewport_.height, readBackBuffer(viewport_)));
}

void Viewer::display() {
  const Simulation& sim = session_.simulation();
  overlay_.hud = hudLine();
  Scene scene{&sim.world(),       &sim.state(),
              &session_.mesh(),   &session_.surfaceSprings(),
              &session_.arrows(), {}};
  if (auto p = session_.pulling())
    scene.pull = std::pair(sim.state().position(p->first), p->second);
  drawFrame(view_, viewport_, scene, overlay_);

  if (screenshotPending_) {
    screenshotPending_ = false;
    screenshot();
  }
  const bool recording = !options_.recordDir.empty();
  if (recording) {
    char name[16];
    std::snprintf(name, sizeof name, "%03d.jpg", framesDrawn_);
    try {
      capture(options_.recordDir / name);
    } catch (const std::exception& e) {
      std::cerr << "jello: " << e.what() << '\n';
      return leave(1);
    }
  }
  glutSwapBuffers();
  if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
    std::cerr << "jello: OpenGL error " << error << '\n';
  }
  ++framesDrawn_;
  ++windowFrames_;

  const Clock::time_point now = Clock::now();
  if (const double span = seconds(now - rateWindow_); span >= 0.5) {
    fps_ = windowFrames_ / span;
    realTimeFactor_ = windowSimTime_ / span;
    windowFrames_ = 0;
    windowSimTime_ = 0.0;
    rateWindow_ = now;
  }

  const int target = recording ? options_.frames : options_.benchmarkFrames;
  if (target > 0) {
    if (recording && ::isatty(STDERR_FILENO)) {
      std::fprintf(stderr, "\rjello: frame %d of %d", framesDrawn_, target);
    }
    if (framesDrawn_ >= target) {
      if (recording) {
        if (::isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
        std::printf("jello: wrote %d frames to %s (t = %.4g s)\n", framesDrawn_,
                    options_.recordDir.c_str(), sim.state().t);
      } else {
        const double elapsed = seconds(now - started_);
        const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        std::printf("%d frames in %.3f s: %.1f frames/s (%s, %dx%d, %s, t = %.4g s; %s)\n",
                    framesDrawn_, elapsed, framesDrawn_ / elapsed,
                    view_.mode == DisplayMode::Shaded ? "shaded" : "wireframe", viewport_.width,
                    viewport_.height, std::string(integratorName(sim.integratorKind())).c_str(),
                    sim.state().t, renderer ? renderer : "unknown renderer");
      }
      return leave(sim.divergence() ? 3 : 0);
    }
  }
  if (!view_.paused) advance();
  if (sim.divergence() && target > 0) return leave(3);
}

void Viewer::screenshot() {
  for (int i = 0; i < 1000; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "jello-%03d.jpg", i);
    if (std::filesystem::exists(name)) continue;
    try {
      capture(name);
      notify(std::string("saved ") + name, false);
    } catch (const std::exception& e) {
      notify(e.what(), true);
    }
    return;
  }
  notify("jello-000.jpg ... jello-999.jpg all exist: screenshot not saved", true);
}

void Viewer::key(unsigned char key) {
  const KeyResult result = handleKey(view_, key);
  Simulation& sim = session_.simulation();
  switch (result.command) {
    case Command::Quit:
      return leave(0);
    case Command::Screenshot:
      screenshotPending_ = true;
      break;
    case Command::Reload:
      if (std::optional<std::string> error = session_.reload()) {
        notify("reload failed, scene kept: " + *error, true);
        std::cerr << "jello: reload failed: " << *error << '\n';
      } else {
        view_.dtScale = 1.0;
        view_.paused = false;
        drag_ = Drag::None;
        notify("reloaded " + options_.source.world.string(), false);
      }
      break;
    case Command::SwitchIntegrator:
      if (!sim.divergence()) {
        sim.setIntegrator(*result.integrator);
        notify("integrator " + std::string(integratorName(*result.integrator)), false);
      }
      break;
    case Command::TimeStep:
      session_.scaleTimeStep(view_.dtScale);
      break;
    case Command::StepOnce:
      if (view_.paused) advance();
      break;
    case Command::None:
      break;
  }
  glutPostRedisplay();
}

void Viewer::mouse(int button, int state, int x, int y) {
  lastX_ = pressX_ = x;
  lastY_ = pressY_ = y;
  if (state == GLUT_UP) {
    drag_ = Drag::None;
    session_.release();
    return;
  }
  if (button == GLUT_RIGHT_BUTTON) {
    drag_ = Drag::Rotate;
  } else if (button == GLUT_LEFT_BUTTON) {
    const State& s = session_.simulation().state();
    const bool pull = view_.pullMode || (glutGetModifiers() & GLUT_ACTIVE_SHIFT);
    if (!pull) {
      drag_ = Drag::Push;
    } else if (auto p = pickPoint(view_.camera, viewport_, session_.mesh(), s, x, y)) {
      drag_ = Drag::Pull;
      anchor_ = s.position(*p);
      session_.pull(*p, anchor_, pullRadius());
    }
  }
}

void Viewer::motion(int x, int y) {
  if (drag_ == Drag::Rotate) view_.camera.rotate(x - lastX_, y - lastY_);
  lastX_ = x;
  lastY_ = y;
  if (drag_ == Drag::Push) {
    session_.push(screenDragToWorld(view_.camera, x - pressX_, y - pressY_) * kPushPerPixel);
  } else if (auto pulled = session_.pulling()) {  // the session keeps the picked point
    session_.pull(pulled->first, dragTarget(view_.camera, viewport_, x, y, anchor_), pullRadius());
  }
}

Viewer* active = nullptr;  // GLUT's callbacks take no context pointer

}  // namespace

int runViewer(const ViewerOptions& options, World world) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') {
    std::cerr << "jello: no display (DISPLAY is not set). Record frames headless under Xvfb:\n"
                 "  xvfb-run -a jello --record frames --frames 300\n";
    return 1;
  }
  if (!options.recordDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.recordDir, ec);
    if (ec) {
      std::cerr << "jello: cannot create " << options.recordDir.string() << ": " << ec.message()
                << '\n';
      return 1;
    }
  }
  int argc = 1;
  char program[] = "jello";
  char* argv[] = {program, nullptr};
  glutInit(&argc, argv);
  glutSetOption(GLUT_ACTION_ON_WINDOW_CLOSE, GLUT_ACTION_GLUTMAINLOOP_RETURNS);
  glutInitDisplayMode(GLUT_DOUBLE | GLUT_RGB | GLUT_DEPTH);
  glutInitWindowSize(options.size.width, options.size.height);
  const int window = glutCreateWindow("jello");
  if (window <= 0) {
    std::cerr << "jello: cannot create a window\n";
    return 1;
  }
  Viewer viewer(options, std::move(world));
  active = &viewer;
  initRenderer();
  glutDisplayFunc([] { active->display(); });
  glutReshapeFunc([](int w, int h) { active->reshape(w, h); });
  glutKeyboardFunc([](unsigned char k, int, int) { active->key(k); });
  glutMouseFunc([](int b, int s, int x, int y) { active->mouse(b, s, x, y); });
  glutMotionFunc([](int x, int y) { active->motion(x, y); });
  glutIdleFunc([] { glutPostRedisplay(); });
  glutMainLoop();
  active = nullptr;
  // The window is still open when the loop returns after glutLeaveMainLoop: close it and let
  // freeglut release its state, so the GL driver's memory is freed before exit.
  if (glutGetWindow() == window) glutDestroyWindow(window);
  glutExit();
  return viewer.exitCode();
}

}  // namespace jello::viewer
