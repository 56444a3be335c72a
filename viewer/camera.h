// The viewer's z-up orbit camera and the screen <-> world maps that picking and dragging use.
// The renderer loads exactly these matrices into GL, so what the tests compute here is what is
// drawn.
//   eye = center + radius (cos(phi) cos(theta), sin(phi) cos(theta), sin(theta)), looking at
//   the centre (the origin until panned), z up; perspective with a vertical field of view fovY (as
//   gluPerspective / gluLookAt).
// Window coordinates are pixels with the origin at the top-left corner, y down (as GLUT's).
#pragma once

#include <Eigen/Core>
#include <numbers>
#include <optional>

#include "src/base/vec3.h"

namespace jello::viewer {

struct Camera {
  double phi = std::numbers::pi / 6;    // rad, azimuth around z
  double theta = std::numbers::pi / 6;  // rad, elevation above the xy-plane, |theta| < pi/2
  double radius = 7.0;                  // m, distance from the centre (the whole box in view)
  Vec3 center{};                        // m, the point looked at (middle-drag pans it)
  double fovY = 60.0;                   // degrees, vertical field of view
  double zNear = 0.01, zFar = 1000.0;   // m
  // m: the eye stays above this height (the box's solid floor is at z = -2): rotating, zooming
  // and panning cannot take it below the floor.
  double minEyeZ = -1.9;

  Vec3 eye() const;
  // Unit vectors of the view: forward (eye to origin), right and up on the screen.
  Vec3 forward() const;
  Vec3 right() const;
  Vec3 up() const;

  // Right-drag: dx, dy in pixels turn the camera.
  void rotate(double dxPixels, double dyPixels);
  // Moves the eye closer (negative) or farther; the radius stays at least 0.5 m.
  void zoom(double metres);
  // Zooms by a factor of the radius (0.9: 10% closer), between 0.5 m and 100 m. Zooming in
  // also moves the point looked at the same share of the way to `focus` (the cube), so zooming
  // closes in on the cube, not on the box's centre.
  void zoomBy(double factor);
  void zoomBy(double factor, const Vec3& focus);
  // Middle-drag: moves the centre so that the scene follows the cursor (at the centre's depth)
  // in a window `viewportHeight` pixels high.
  void pan(double dxPixels, double dyPixels, int viewportHeight);
  // Follow mode (key c, --follow): moves the point looked at `share` (0..1) of the way to
  // `target` (the cube's centre) and turns the eye about the box's vertical axis by as much as
  // that point turned about it (so the eye stays on its side of the cube), keeping the eye above
  // the floor; once a frame, so the camera eases after the cube instead of jumping with it.
  void follow(const Vec3& target, double share);
  // Raises the elevation just enough that the eye is at minEyeZ or above (the others call it).
  void keepAboveFloor();
};

// Follow mode's distance: close enough that the cube is a sixth of the view's height, far
// enough that what it touches is in view too.
inline constexpr double kFollowRadius = 4.5;  // m
// Follow mode's easing: the camera closes 1 - exp(-elapsed / kFollowSeconds) of the gap to the
// cube in `elapsed` wall seconds (recorded frames: 1/15 s each).
inline constexpr double kFollowSeconds = 0.3;

struct Viewport {
  int width = 640, height = 480;  // pixels
  double aspect() const { return double(width) / double(height); }
};

// Column-major 4x4 matrices, ready for glLoadMatrixd.
Eigen::Matrix4d viewMatrix(const Camera& camera);
Eigen::Matrix4d projectionMatrix(const Camera& camera, const Viewport& viewport);

struct ScreenPoint {
  double x, y;   // pixels from the top-left corner
  double depth;  // m along the view direction from the eye
};
// Where a world point appears; nothing when it is behind the eye.
std::optional<ScreenPoint> project(const Camera& camera, const Viewport& viewport, const Vec3& p);

struct Ray {
  Vec3 origin;     // the eye
  Vec3 direction;  // unit
};
// The ray from the eye through pixel (x, y).
Ray pixelRay(const Camera& camera, const Viewport& viewport, double x, double y);

// Where the ray through pixel (x, y) meets the plane through `anchor` facing the camera: the
// point a picked point is pulled towards.
Vec3 dragTarget(const Camera& camera, const Viewport& viewport, double x, double y,
                const Vec3& anchor);

// A drag of (dx, dy) pixels as a world direction in the screen's plane (not normalized: one
// unit per pixel), y down on the screen mapping to -up.
Vec3 screenDragToWorld(const Camera& camera, double dxPixels, double dyPixels);

}  // namespace jello::viewer
