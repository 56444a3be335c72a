#include "viewer/viewer_app.h"

#include <GL/freeglut.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <thread>

#include "viewer/interaction.h"
#include "viewer/viewer_window.h"

namespace jello::viewer {
namespace window {

std::string Viewer::restartHint() const {
  if (group_) return " - press r to reload the world for every pane";
  return " - press r to reload the world (then a number key or n picks an integrator, - a "
         "smaller time step)";
}

std::string Viewer::hudLine(std::size_t pane) const {
  const Frame& f = frames_[pane];
  std::ostringstream os;
  if (group_) {
    // One compact line a pane (five wrapped lines covered a third of a 640x480 pane); the
    // group's pace on the first pane's second line.
    // A step the panes share is said once, on the first pane's second line.
    const bool shared = std::all_of(frames_.begin(), frames_.end(),
                                    [&](const Frame& other) { return other.dt == f.dt; });
    os << integratorName(f.integrator);
    if (!shared) os << " dt " << format("%.2g", f.dt * 1e3) << "ms";
    os << " t " << format("%.3f", f.state.t) << " E " << format("%.3g", f.energy.total()) << "J";
    if (pane > 0) return os.str();
    os << "\n";
    if (shared) os << "dt " << format("%.2g", f.dt * 1e3) << " ms  ";
    os << (options_.courseTime ? std::string("course time")
                               : "speed " + format("%.4g", f.speed) + "x");
    if (recording()) {
      os << "  frame " << framesDrawn_ + 1 << "/" << options_.frames;
    } else {
      os << "  " << format("%.0f", fps_) << " fps";
      if (!view_.paused && !options_.courseTime && group_->rateSpan() >= 0.25 &&
          group_->rate() < 0.9 * f.speed) {
        os << "  behind: " << format("%.3g", group_->rate()) << " s per wall s";
      }
    }
    if (view_.paused) os << "  [paused]";
    if (view_.pullMode || drag_ == Drag::Pull)
      os << "  pull radius " << pullRadiusText(pullRadius());
    return os.str();
  }
  os << integratorName(f.integrator) << "  dt " << format("%.3g", f.dt) << " s  t "
     << format("%.3f", f.state.t) << " s  ";
  if (options_.courseTime) {
    os << "course time (n*dt per frame)";
  } else {
    os << "speed " << format("%.4g", f.speed) << "x";
  }
  // A recording's frames are not drawn in real time: its progress, not a frame rate ("0 fps").
  if (recording()) {
    os << "  frame " << framesDrawn_ + 1 << "/" << options_.frames;
  } else {
    os << "  " << format("%.0f", fps_) << " fps";
  }
  os << "  E " << format("%.4g", f.energy.total()) << " J";
  const bool behind = f.lagging && !f.paused && !f.divergence;
  // Judged over a quarter second at least: right after a reload there is no rate yet.
  const bool slow = !options_.courseTime && !recording() && !f.paused && f.rateSpan >= 0.25 &&
                    f.simRate < 0.9 * f.speed && !f.divergence;
  if (behind || slow) {
    os << "\nbehind: simulating " << format("%.3g", f.simRate) << " s per wall second (speed asks "
       << format("%.4g", f.speed) << ")";
  }
  if (pane > 0) return os.str();  // the first pane says the rest
  if (view_.paused || view_.pullMode || drag_ == Drag::Pull) os << '\n';
  if (view_.paused) os << "[paused]  ";
  if (view_.pullMode || drag_ == Drag::Pull) {
    os << "pull radius " << pullRadiusText(pullRadius());
  }
  return os.str();
}

Overlay Viewer::overlay(std::size_t pane) const {
  Overlay o;
  o.hud = hudLine(pane);
  o.compactHud = group_ != nullptr;
  if (view_.showHelp && pane == 0) o.help = "Keys and mouse (? closes):\n" + keyTable();
  const double age = seconds(Clock::now() - messageTime_);
  const double life = alarm_ ? kAlarmSeconds : kNoticeSeconds;
  if (frames_[pane].divergence) {  // stays until the scene is restarted
    o.message = *frames_[pane].divergence + restartHint();
    // A key pressed meanwhile is answered too (an integrator key said nothing after this).
    if (pane == 0 && !message_.empty() && age < life) o.message = message_ + "\n" + o.message;
    o.alarm = true;
    return o;
  }
  if (pane > 0) return o;
  o.message = message_;
  o.alarm = alarm_;
  o.messageAlpha =
      static_cast<float>(std::clamp((life + kFadeSeconds - age) / kFadeSeconds, 0.0, 1.0));
  return o;
}

Scene Viewer::scene(std::size_t pane) const {
  const Frame& f = frames_[pane];
  const SceneGeometry& g = *f.geometry;
  Scene s;
  s.world = &g.world;
  s.state = &f.state;
  s.mesh = &g.mesh;
  s.springs = &g.springs;
  s.arrows = &g.arrows;
  s.friction = &f.friction;
  if (view_.texture) s.texture = &texture_;
  if (f.pull) {
    s.pull = std::pair(f.state.position(f.pull->first), f.pull->second);
    s.pullRadius = pullRadius();
  }
  if (drag_ == Drag::Push && norm(pushAccel_) > 0.0) {
    Vec3 centre;
    const int n = f.state.numPoints();
    for (int p = 0; p < n; ++p) centre = centre + f.state.position(p);
    centre = centre * (1.0 / n);
    s.push = std::pair(centre, centre + pushAccel_ * 0.1);  // 10 cm per m/s^2
  }
  return s;
}

void Viewer::takeNotices() {
  forEachRunner([&](SimRunner& r) {
    for (Notice& n : r.takeNotices()) {
      if (n.alarm) std::cerr << "jello: " << n.text << '\n';
      notify(std::move(n.text), n.alarm);
    }
  });
}

void Viewer::waitForRecordedFrame() {
  // Frame i shows simulated time t0 + i * span: 300 frames play 20 s of animation at speed 1.
  const double goal = recordStart_ + framesDrawn_ * recordSpan_;
  if (group_) group_->setTarget(goal);
  forEachRunner([&](SimRunner& r) {
    r.setTarget(goal);
    while (!r.waitFor(goal, 0.5)) {
      if (r.frame().divergence) return;
      if (::isatty(STDERR_FILENO)) {
        std::fprintf(stderr, "\rjello: frame %d of %d (simulating t = %.4g s)", framesDrawn_ + 1,
                     options_.frames, r.frame().state.t);
      }
    }
  });
}

Viewport Viewer::sceneViewport() const {
  if (group_ || !view_.showPanel || panel_.width() <= 0) return viewport_;
  return {std::max(1, viewport_.width - panel_.width()), viewport_.height};
}

void Viewer::drawPanes() {
  if (!group_) {
    drawFrame(view_, sceneViewport(), scene(0), overlay(0));
    return;
  }
  const std::vector<Pane> panes = paneLayout(int(group_->size()), viewport_);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);  // the gaps between panes
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  for (std::size_t i = 0; i < panes.size(); ++i) {
    // A one-pixel gutter between panes.
    const Viewport inner{std::max(1, panes[i].size.width - 1),
                         std::max(1, panes[i].size.height - 1)};
    drawFrame(view_, inner, scene(i), overlay(i), panes[i].x, panes[i].y);
  }
  glViewport(0, 0, viewport_.width, viewport_.height);
}

void Viewer::capture(const std::filesystem::path& path) {
  writeJpeg(path, imageFromBottomUp(viewport_.width, viewport_.height, readBackBuffer(viewport_)));
}

void Viewer::recordFrame() {
  const Image image =
      imageFromBottomUp(viewport_.width, viewport_.height, readBackBuffer(viewport_));
  if (!options_.recordDir.empty()) {
    writeJpeg(options_.recordDir / recordedFrameName(framesDrawn_), image);
  }
  if (!options_.recordVideo.empty()) {
    if (!video_) {
      video_ = std::make_unique<VideoWriter>(options_.recordVideo, image.width, image.height,
                                             kRecordedFramesPerSecond);
    }
    video_->add(image);
  }
}

// Long: one frame's drawing, pane by pane, in the order GL needs it.
void Viewer::display() {
  if (recording()) waitForRecordedFrame();
  if (group_ && !recording()) {
    if (options_.courseTime) {
      if (!view_.paused && group_->allReached()) group_->advanceBy(primary().geometry->frameTime);
    } else {
      group_->tick(seconds(Clock::now() - started_));
    }
  }
  // Compare mode: every pane at the instant all reached (the faster ones may be ahead), so the
  // panes show one simulated time; a recording waited for all to reach its frame's time.
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    std::optional<Frame> at;
    if (group_ && !recording()) at = runner(i).frameAt(group_->shown());
    frames_[i] = at ? std::move(*at) : runner(i).frame();
  }
  // Zooming in closes on the (first pane's) cube; follow mode eases the camera after it, by the
  // wall time since the last frame (a recorded frame's: 1/15 s, so recordings repeat exactly).
  view_.focus = primary().state.centroid();
  if (view_.follow) {
    const double elapsed = recording() ? 1.0 / kRecordedFramesPerSecond
                                       : std::min(seconds(Clock::now() - lastDraw_), 1.0);
    view_.camera.follow(view_.focus, 1.0 - std::exp(-elapsed / kFollowSeconds));
  }
  if (const long published = runner().published(); published != drawnPublished_) {
    drawnPublished_ = published;
    panel_.sample(seconds(Clock::now() - started_), primary());
  }
  takeNotices();
  // One integrator diverging pauses a single view; in compare mode the others go on.
  const bool stopped = group_ ? std::all_of(frames_.begin(), frames_.end(),
                                            [](const Frame& f) { return f.divergence; })
                              : primary().divergence.has_value();
  if (stopped && !divergenceShown_) {
    divergenceShown_ = true;
    view_.paused = true;
  }
  if (!stopped) divergenceShown_ = false;
  if (!group_) panel_.prepare(primary(), view_, runner());  // its width first: the scene's beside
  drawPanes();
  if (!group_) panel_.render();
  lastDraw_ = Clock::now();

  if (screenshotPending_) {
    screenshotPending_ = false;
    screenshot();
  }
  if (recording()) {
    try {
      recordFrame();
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
  if (options_.courseTime && !view_.paused && !group_) {
    runner().advanceTarget(primary().geometry->frameTime);
  }

  const Clock::time_point now = Clock::now();
  if (const double span = seconds(now - rateWindow_); span >= 0.5) {
    fps_ = windowFrames_ / span;
    windowFrames_ = 0;
    rateWindow_ = now;
  }

  const int target = recording() ? options_.frames : options_.benchmarkFrames;
  if (target > 0) {
    if (recording() && ::isatty(STDERR_FILENO)) {
      std::fprintf(stderr, "\rjello: frame %d of %d (t = %.4g s)          ", framesDrawn_, target,
                   primary().state.t);
    }
    if (stopped) return leave(3);
    if (framesDrawn_ >= target) {
      if (recording()) {
        if (::isatty(STDERR_FILENO)) std::fprintf(stderr, "\n");
        if (video_) {
          try {
            video_->finish();
          } catch (const std::exception& e) {
            std::cerr << "jello: " << e.what() << '\n';
            return leave(1);
          }
        }
        const std::string where =
            options_.recordDir.empty() ? options_.recordVideo.string()
            : options_.recordVideo.empty()
                ? options_.recordDir.string()
                : options_.recordDir.string() + " and " + options_.recordVideo.string();
        std::printf(
            "jello: wrote %d frames to %s: simulated t = %.4g .. %.4g s (%s, %.4g s per frame; "
            "%.4g s of animation at 15 frames/s)\n",
            framesDrawn_, where.c_str(), recordStart_, latestTime(),
            options_.courseTime ? "course time" : ("speed " + format("%.4g", view_.speed)).c_str(),
            recordSpan_, framesDrawn_ / kRecordedFramesPerSecond);
        if (view_.showPanel && !group_) {
          std::printf("jello: the panel %d px wide beside the scene's %d, %s\n", panel_.width(),
                      sceneViewport().width,
                      panel_.labelsCut() ? "a line cut at its edge" : "every label whole");
        }
      } else {
        const double elapsed = seconds(now - started_);
        const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        GLint samples = 0;
        glGetIntegerv(GL_SAMPLES, &samples);
        std::printf(
            "%d frames in %.3f s: %.1f frames/s (%s, %dx%d, %d samples, panel %s, %s, t = %.4g s, "
            "simulating %.3g s per wall second%s; %s)\n",
            framesDrawn_, elapsed, framesDrawn_ / elapsed,
            view_.mode == DisplayMode::Shaded ? "shaded" : "wireframe", viewport_.width,
            viewport_.height, samples, view_.showPanel ? "open" : "hidden",
            std::string(integratorName(primary().integrator)).c_str(), primary().state.t,
            primary().state.t / elapsed, primary().lagging ? ", lagging" : "",
            renderer ? renderer : "unknown renderer");
      }
      return leave(0);
    }
  }
}

void Viewer::idle() {
  if (recording() || options_.benchmarkFrames > 0) return glutPostRedisplay();
  // Paused with nothing new to show: idle instead of redrawing the same picture.
  const bool fading = !message_.empty() &&
                      seconds(Clock::now() - messageTime_) < kAlarmSeconds + kFadeSeconds + 0.1;
  const bool still = (view_.paused || primary().divergence) && drag_ == Drag::None && !fading &&
                     runner().published() == drawnPublished_;
  if (still) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return;
  }
  const double wait = 1.0 / kInteractiveFps - seconds(Clock::now() - lastDraw_);
  if (wait > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  glutPostRedisplay();
}

void Viewer::screenshot() {
  const std::optional<std::string> name = freeName("jello-%03d.jpg");
  if (!name) return notify("jello-000.jpg ... jello-999.jpg all exist: screenshot not saved", true);
  try {
    capture(*name);
    notify("saved " + *name, false);
  } catch (const std::exception& e) {
    notify(e.what(), true);
  }
}

}  // namespace window

namespace {

window::Viewer* active = nullptr;  // GLUT's callbacks take no context pointer

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
  glutSetOption(GLUT_MULTISAMPLE, 4);
  glutInitDisplayMode(GLUT_DOUBLE | GLUT_RGB | GLUT_DEPTH | GLUT_STENCIL | GLUT_MULTISAMPLE);
  // Interactively the panel opens beside the scene: without --size, the window is wider by
  // the panel's column at its default text size, so the scene keeps the course's 640x480.
  const bool interactive =
      options.recordDir.empty() && options.recordVideo.empty() && options.benchmarkFrames == 0;
  const bool besidePanel =
      interactive && !options.sizeGiven && options.compare.empty() && options.panel.value_or(true);
  glutInitWindowSize(
      options.size.width + (besidePanel ? int(std::lround(kPanelColumn * options.uiScale)) : 0),
      options.size.height);
  const int window = glutCreateWindow("jello");
  if (window <= 0) {
    std::cerr << "jello: cannot create a window\n";
    return 1;
  }
  int exitCode = 0;
  {
    window::Viewer viewer(options, std::move(world));
    active = &viewer;
    initRenderer();
    glutDisplayFunc([] { active->display(); });
    glutReshapeFunc([](int w, int h) { active->reshape(w, h); });
    glutKeyboardFunc([](unsigned char k, int, int) { active->key(k); });
    glutMouseFunc([](int b, int s, int x, int y) { active->mouse(b, s, x, y); });
    glutMotionFunc([](int x, int y) { active->motion(x, y); });
    glutPassiveMotionFunc([](int x, int y) { active->passiveMotion(x, y); });
    glutKeyboardUpFunc([](unsigned char k, int x, int y) { active->keyUp(k, x, y); });
    glutSpecialFunc([](int k, int x, int y) { active->special(k, x, y, true); });
    glutSpecialUpFunc([](int k, int x, int y) { active->special(k, x, y, false); });
    glutIdleFunc([] { active->idle(); });
    glutMainLoop();
    active = nullptr;
    exitCode = viewer.exitCode();
    // The window goes at once; the simulation thread may still finish a factorization (it
    // cannot be cut short) while the viewer is taken down below.
    if (glutGetWindow() == window) {
      glutHideWindow();
      glutMainLoopEvent();
    }
  }  // the simulation thread stops here, a long step cut short
  // The window is still open when the loop returns after glutLeaveMainLoop: close it and let
  // freeglut release its state, so the GL driver's memory is freed before exit.
  if (glutGetWindow() == window) glutDestroyWindow(window);
  glutExit();
  return exitCode;
}

}  // namespace jello::viewer
