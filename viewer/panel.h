// The live panel (Dear ImGui over GLUT and OpenGL 2): the integrator and its time step, the
// playback speed, the world's constants, the obstacles, the pull, live plots of the energies,
// the angular momentum and the solver's effort over the last seconds, and the solver's counters.
// Edits go to the simulation thread as commands; nothing here waits for a step.
#pragma once

#include <array>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer/sim_runner.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {

// The vertical range a plot of `data` is drawn over: its own, widened to at least relativeFloor
// times its largest magnitude (1e-12 at least), so that round-off does not fill the plot.
std::pair<float, float> plotRange(const std::vector<float>& data, double relativeFloor);

// The plotted quantities over a sliding window of simulated time, one sample per new frame.
struct PlotHistory {
  static constexpr double kWindow = 10.0;  // wall seconds kept
  enum Series { Kinetic, Spring, Contact, Field, Total, AngularMomentum, Effort, StepSize, kCount };
  static constexpr std::array<const char*, kCount> kNames{
      "kinetic (J)", "spring (J)",     "contact (J)",          "field (J)",
      "total (J)",   "|L| (relative)", "solver effort / step", "CVODE step (s)"};
  std::deque<double> wall;
  std::array<std::deque<float>, kCount> values;
  std::string effortName;  // which counter the effort is of ("newton_iterations", ...)

  // Adds a sample for `frame` (once per published frame), dropping samples older than kWindow.
  void add(double wallTime, const Frame& frame);
  void clear();

 private:
  long lastSteps_ = -1;
  double lastEffort_ = 0.0;
};

// The panel's text size in pixels for a window `height` pixels high: ImGui's 13 px at the
// course's 480 and below, growing with the window up to three times that, times `uiScale`
// (--ui-scale), rounded to whole pixels.
float panelFontPixels(int height, double uiScale);
// The panel's width at 13 px text on jello.w, its sections closed (as the viewer reports it
// after a recording with --panel): the column an interactive window opens wider by, so the
// scene keeps its size beside it.
inline constexpr double kPanelColumn = 248.0;  // pixels

// Clicks shorter than a frame (ImGui 1.86 reads a button's state once a frame: a press and its
// release between two frames were never seen): a release whose press no frame has seen yet is
// held back, and handed out after the next frame. GL-free, so it is unit-tested.
class ClickLatch {
 public:
  struct Release {
    int button, x, y;
  };
  // A button event (buttons 0-2; others pass): true to forward it now, false when held back.
  bool event(int button, bool down, int x, int y);
  // A frame has seen the events forwarded so far: the releases held back, to forward now.
  std::vector<Release> frameSeen();

 private:
  std::array<bool, 3> pressUnseen_{}, held_{};
  std::array<Release, 3> releases_{};
};

class Panel {
 public:
  // After the GL window exists. `uiScale` (--ui-scale) multiplies the text and spacing.
  explicit Panel(double uiScale = 1.0);
  ~Panel();
  Panel(const Panel&) = delete;
  Panel& operator=(const Panel&) = delete;

  // Input, forwarded first: true when the panel takes it (the pointer is over it, or a text
  // field has the keyboard).
  bool mouse(int button, int state, int x, int y);
  bool motion(int x, int y);
  void passiveMotion(int x, int y);
  bool key(unsigned char c, int x, int y);
  void keyUp(unsigned char c, int x, int y);
  void special(int key, int x, int y, bool down);
  void reshape(int w, int h);

  // Records a sample of a newly published frame.
  void sample(double wallTime, const Frame& frame) { history_.add(wallTime, frame); }
  // Lays the panel out (when view.showPanel), before the scene is drawn, so that width() is
  // this frame's; edits go to `runner`. Then render() draws it over the scene.
  void prepare(const Frame& frame, ViewerState& view, SimRunner& runner);
  void render();
  // The panel is a column at the window's right edge, its whole height, as wide as its widest
  // line (labels are never cut): its width in pixels as last drawn (0 hidden or not yet drawn).
  // The scene is drawn beside it, in the rest of the window.
  int width() const { return width_; }
  // Whether a line of the last drawn panel did not fit its width (false: every label whole).
  bool labelsCut() const { return labelsCut_; }

 private:
  void build(const Frame& frame, ViewerState& view, SimRunner& runner);
  void syncFromWorld(const Frame& frame);
  void constants(const Frame& frame, SimRunner& runner);
  void plots(const Frame& frame);
  void solverOptions(const Frame& frame, SimRunner& runner);

  PlotHistory history_;
  long generation_ = -1;
  // Slider values, taken from the world when the scene is replaced.
  float k_ = 0, d_ = 0, kCollision_ = 0, dCollision_ = 0, mass_ = 0, fieldScale_ = 1;
  ContactLaw contact_;
  float contactLayer_ = float(kDefaultContactLayer);
  float dhat_ = float(kDefaultBarrierDistance);
  float kappa_ = 400.0f;  // N/m: the world's kCollision until it is synced
  float mu_ = 0.0f;
  float dt_ = 0;
  float pullScale_ = 1;
  SolverOptions options_;  // the solver section's copy while editing
  float newtonTolerance_ = 1e-8f, rtol_ = 1e-6f, chebyshevRho_ = 0.0f;
  float seedTolerance_ = 1e-4f, seedChebyshevRho_ = 0.0f;
  std::optional<Plane> savedPlane_;
  std::optional<Sphere> savedSphere_;
  bool plane_ = false, sphere_ = false;
  bool warmedUp_ = false;
  double uiScale_ = 1.0;
  float fontPixels_ = 0.0f;  // the font atlas's size (rebuilt when the window's height asks)
  int width_ = 0;
  bool labelsCut_ = false;
  ClickLatch clicks_;
  void scaleTo(int height);
};

}  // namespace jello::viewer
