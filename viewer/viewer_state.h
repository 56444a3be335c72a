// Everything the viewer's keys change, and the keys themselves, free of GL: the GLUT callbacks
// only forward keys here and act on the returned command, so key handling is unit-tested.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "src/world/integrator_table.h"
#include "viewer/camera.h"

namespace jello::viewer {

enum class DisplayMode { Shaded, Wireframe };

struct ViewerState {
  Camera camera;
  DisplayMode mode = DisplayMode::Shaded;
  bool structural = true;  // wireframe: springs of each kind drawn
  bool shear = false;
  bool bend = false;
  bool paused = false;
  bool showField = false;  // force-field arrows
  bool showHud = true;     // the heads-up line
  bool pullMode = false;   // left-drag pulls the picked point (also with Shift held)
  int pullRadius = 0;      // index into pullRadii()
  Vec3 focus;              // what zooming in closes on: the cube's centre (the viewer sets it)
  double dtScale = 1.0;    // the time step is the starting one times this
  double speed = 1.0;      // playback: simulated seconds per wall second (real time)
  bool showPanel = true;   // the ImGui panel
  bool showHelp = false;   // the key table on screen
  bool texture = false;    // the shaded cube textured
  bool follow = false;     // the camera follows the cube (key c, --follow)
};

inline constexpr double kMinSpeed = 1.0 / 1024, kMaxSpeed = 64.0;

enum class Command {
  None,              // the state changed (or nothing did); redraw
  Quit,              // ESC
  Screenshot,        // space
  Reload,            // r: read the world file again
  SwitchIntegrator,  // 1-9, 0: see KeyResult::integrator
  NextIntegrator,    // n: the one after the current in the table, cyclically
  TimeStep,          // + / -: dtScale changed
  StepOnce,          // . : one frame while paused
  Pause,             // p: paused changed
  Speed,             // < >: speed changed
  SaveWorld,         // w: save the current state as a world file
  PullRadius,        // [ ]: pullRadius changed (said on screen at once)
};

struct KeyResult {
  Command command = Command::None;
  std::optional<IntegratorKind> integrator;
};

// Applies key `key` to the state; unknown keys do nothing.
KeyResult handleKey(ViewerState& state, unsigned char key);

// The integrator after `kind` in the table, the first after the last (key n).
IntegratorKind nextIntegrator(IntegratorKind kind);

struct KeyBinding {
  std::string keys;
  std::string action;
};
// The key table, one source for --help, the README and the on-screen help.
std::span<const KeyBinding> keyBindings();
std::string keyTable();  // "  keys  action" lines

// The heads-up text as lines of at most `width` characters, broken at '\n' and, when too
// long, at the last space that fits (or hard, when there is none).
// Lines continuing an over-long one start with `hanging` spaces (the key table's action column).
std::vector<std::string> wrapText(const std::string& text, std::size_t width,
                                  std::size_t hanging = 0);
// A pull radius as the heads-up and the notices say it: "one point", "0.25 m", "whole cube".
std::string pullRadiusText(double radius);

// Course time: simulated seconds to advance per displayed frame, split into whole steps of at
// most dt: the frame time is the world's n*dt0 (fixed when +/- change dt), at least one step.
int stepsPerFrame(double frameTime, double dt);

// Compare mode: the window split into `count` panes, left to right, then top to bottom (one row
// for up to three, then two rows). Each pane's lower-left corner is in GL's window coordinates
// (y up).
struct Pane {
  int x = 0, y = 0;
  Viewport size;
};
std::vector<Pane> paneLayout(int count, const Viewport& window);
// The pane under window pixel (x, y) (GLUT's coordinates: y down), and the pixel in the pane's
// own coordinates (y down); nothing outside every pane.
struct PanePixel {
  int pane;
  double x, y;
};
std::optional<PanePixel> paneAt(const std::vector<Pane>& panes, const Viewport& window, double x,
                                double y);

// Recorded animations play at the course's 15 frames per second: each recorded frame covers
// speed/15 simulated seconds, or the world's n*dt in course time.
inline constexpr double kRecordedFramesPerSecond = 15.0;
double recordedFrameSpan(double speed, bool courseTime, double courseFrameTime);

}  // namespace jello::viewer
