// Draws one frame with OpenGL's fixed-function pipeline (Mesa's llvmpipe runs it headless):
// the box, the cube shaded with per-vertex normals or as a wireframe of its surface springs,
// the inclined plane and the sphere clipped to the box, field arrows, and the heads-up text.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "src/state.h"
#include "src/world/world.h"
#include "viewer/box_geometry.h"
#include "viewer/camera.h"
#include "viewer/image_writer.h"
#include "viewer/surface.h"
#include "viewer/viewer_state.h"

namespace jello::viewer {

// The background colour: tests look for it.
inline constexpr float kBackground[3] = {0.10f, 0.11f, 0.14f};
inline constexpr float kFloor[3] = {0.20f, 0.21f, 0.25f};  // the box's solid floor

struct Scene {
  const World* world = nullptr;  // plane, sphere
  const State* state = nullptr;  // positions to draw (always a sane state)
  const SurfaceMesh* mesh = nullptr;
  const std::vector<Spring>* springs = nullptr;  // surface springs
  const std::vector<Arrow>* arrows = nullptr;    // field arrows
  const std::vector<Arrow>* friction = nullptr;  // friction's forces, shown with the field's
  std::optional<std::pair<Vec3, Vec3>> pull;     // picked point and its target, while pulling
  double pullRadius = 0.0;                       // m, the pull's fall-off radius (rest length)
  std::optional<std::pair<Vec3, Vec3>> push;     // from the cube's centre along the push
  const Image* texture = nullptr;                // shaded cube textured with it (key t)
};

struct Overlay {
  std::string hud;            // the heads-up line
  std::string message;        // an error or notice, drawn in its own colour on a dark backing
  bool alarm = false;         // the message is an error (red) rather than a notice
  float messageAlpha = 1.0f;  // fades out
  std::string help;           // drawn in the middle when not empty (the key table)
  bool compactHud = false;    // the heads-up in a small proportional font (compare panes)
};

// Once, after the window exists: depth test, lights, materials.
void initRenderer();
// Draws into the pane of size `viewport` whose lower-left corner is (x0, y0) in the window
// (GL's window coordinates: y up); the rest of the window is left alone.
void drawFrame(const ViewerState& view, const Viewport& viewport, const Scene& scene,
               const Overlay& overlay, int x0 = 0, int y0 = 0);

// The back buffer's pixels, bottom row first (GL order), RGB.
std::vector<std::uint8_t> readBackBuffer(const Viewport& viewport);

}  // namespace jello::viewer
