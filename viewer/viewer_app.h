// The interactive viewer: a GLUT window over one Simulation, with the keys of viewer_state.h,
// mouse push and pull, reload, screenshots, recording to numbered JPEGs and a frame-rate
// benchmark. The only file besides renderer.cpp that talks to GLUT.
#pragma once

#include <filesystem>
#include <optional>

#include "src/integrator_name.h"
#include "src/world.h"
#include "viewer/camera.h"
#include "viewer/viewer_session.h"

namespace jello::viewer {

inline constexpr int kMaxRecordedFrames = 300;  // the course's rule: 15 frames per second

struct ViewerOptions {
  SceneSource source;               // the world file and its overrides
  std::filesystem::path recordDir;  // non-empty: record `frames` frames and exit
  int frames = 0;
  Viewport size;
  bool realTime = false;   // advance by wall-clock time instead of n*dt per frame
  bool wireframe = false;  // start in wireframe
  bool hud = true;
  int benchmarkFrames = 0;  // > 0: draw this many frames as fast as possible, print frames/s
};

// Runs the viewer on an already loaded world. Returns the exit code: 0, 1 (no display, a
// frame that could not be written), 3 (the simulation diverged while recording/benchmarking).
int runViewer(const ViewerOptions& options, World world);

}  // namespace jello::viewer
