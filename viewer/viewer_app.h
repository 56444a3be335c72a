// The interactive viewer: a GLUT window over a SimRunner (the simulation on its own thread),
// with the keys of viewer_state.h, mouse push and pull, reload, screenshots, recording to
// numbered JPEGs and/or a video (15 frames per simulated second times the speed) and a
// frame-rate benchmark. The only
// file besides renderer.cpp and panel.cpp that talks to GLUT.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "src/world/integrator_table.h"
#include "src/world/world.h"
#include "viewer/camera.h"
#include "viewer/viewer_session.h"

namespace jello::viewer {

inline constexpr int kMaxRecordedFrames = 300;  // the course's rule: 15 frames per second

struct ViewerOptions {
  SceneSource source;                 // the world file and its overrides
  std::filesystem::path recordDir;    // non-empty: record `frames` frames and exit
  std::filesystem::path recordVideo;  // non-empty: the same frames as a video (.mp4, .webm)
  int frames = 0;
  Viewport size;
  bool sizeGiven = true;    // --size given; else an interactive window with the panel is wider
  double uiScale = 1.0;     // --ui-scale: the panel's text and spacing, times its window's scale
  double speed = 1.0;       // playback: simulated seconds per wall second
  bool courseTime = false;  // the original pacing: the world's n*dt per displayed frame
  bool wireframe = false;   // start in wireframe
  bool field = false;       // start with the field arrows shown
  bool follow = false;      // start with the camera following the cube (key c)
  std::filesystem::path texture;  // non-empty: this image ("builtin": ours) from the start
  bool hud = true;
  std::optional<bool> panel;            // unset: shown interactively, hidden in recordings
  std::vector<IntegratorKind> compare;  // 2-6: these integrators side by side
  bool compareSameStep = false;  // --compare-dt same: every pane at the world's (or --dt's) step
  int benchmarkFrames = 0;       // > 0: draw this many frames as fast as possible, print frames/s
};

// Runs the viewer on an already loaded world. Returns the exit code: 0, 1 (no display, a
// frame that could not be written), 3 (the simulation diverged while recording/benchmarking).
int runViewer(const ViewerOptions& options, World world);

}  // namespace jello::viewer
