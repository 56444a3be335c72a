#include "viewer/camera.h"

#include <algorithm>
#include <cmath>

namespace jello::viewer {
namespace {

Vec3 normalized(const Vec3& v) {
  return v * (1.0 / norm(v));
}

double tanHalfFov(const Camera& c) {
  return std::tan(c.fovY * std::numbers::pi / 360.0);
}

}  // namespace

Vec3 Camera::eye() const {
  return center + Vec3{radius * std::cos(phi) * std::cos(theta),
                       radius * std::sin(phi) * std::cos(theta), radius * std::sin(theta)};
}

Vec3 Camera::forward() const {
  return normalized(center - eye());
}

Vec3 Camera::right() const {
  return normalized(cross(forward(), Vec3{0.0, 0.0, 1.0}));
}

Vec3 Camera::up() const {
  return cross(right(), forward());
}

void Camera::rotate(double dxPixels, double dyPixels) {
  // As the original assignment's viewer: 0.01 rad per pixel on both angles.
  phi += 0.01 * dxPixels;
  const double limit = std::numbers::pi / 2 - 0.01;  // z-up stays defined
  theta = std::clamp(theta + 0.01 * dyPixels, -limit, limit);
  keepAboveFloor();
}

void Camera::zoom(double metres) {
  radius = std::max(0.5, radius + metres);
  keepAboveFloor();
}

void Camera::zoomBy(double factor) {
  radius = std::clamp(radius * factor, 0.5, 100.0);
  keepAboveFloor();
}

void Camera::zoomBy(double factor, const Vec3& focus) {
  if (factor < 1.0) center = center + (focus - center) * (1.0 - factor);
  zoomBy(factor);
}

void Camera::pan(double dxPixels, double dyPixels, int viewportHeight) {
  const double metresPerPixel = 2.0 * radius * tanHalfFov(*this) / std::max(viewportHeight, 1);
  center = center - (right() * dxPixels - up() * dyPixels) * metresPerPixel;
  center.z = std::max(center.z, minEyeZ);  // the point looked at stays above the floor too
  keepAboveFloor();
}

void Camera::follow(const Vec3& target, double share) {
  const Vec3 before = center;
  center = center + (target - center) * std::clamp(share, 0.0, 1.0);
  center.z = std::max(center.z, minEyeZ);
  // The eye turns about the box's vertical axis as the point looked at does, so it keeps its
  // side of the cube (outside, where nothing is between them) however the cube goes round.
  // Near the axis a bearing means nothing: there the eye keeps its azimuth.
  constexpr double kNearAxis = 0.25;  // m
  if (std::hypot(before.x, before.y) > kNearAxis && std::hypot(center.x, center.y) > kNearAxis) {
    const double turn = std::atan2(center.y, center.x) - std::atan2(before.y, before.x);
    phi += std::remainder(turn, 2.0 * std::numbers::pi);
  }
  keepAboveFloor();
}

void Camera::keepAboveFloor() {
  if (eye().z >= minEyeZ) return;
  const double limit = std::numbers::pi / 2 - 0.01;
  theta =
      std::clamp(std::asin(std::clamp((minEyeZ - center.z) / radius, -1.0, 1.0)), -limit, limit);
}

Eigen::Matrix4d viewMatrix(const Camera& c) {
  const Vec3 e = c.eye(), f = c.forward(), s = c.right(), u = c.up();
  Eigen::Matrix4d m;
  m << s.x, s.y, s.z, -dot(s, e),   //
      u.x, u.y, u.z, -dot(u, e),    //
      -f.x, -f.y, -f.z, dot(f, e),  //
      0.0, 0.0, 0.0, 1.0;
  return m;
}

Eigen::Matrix4d projectionMatrix(const Camera& c, const Viewport& viewport) {
  const double f = 1.0 / tanHalfFov(c), n = c.zNear, far = c.zFar;
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = f / viewport.aspect();
  m(1, 1) = f;
  m(2, 2) = (far + n) / (n - far);
  m(2, 3) = 2.0 * far * n / (n - far);
  m(3, 2) = -1.0;
  return m;
}

std::optional<ScreenPoint> project(const Camera& c, const Viewport& viewport, const Vec3& p) {
  const Eigen::Vector4d clip =
      projectionMatrix(c, viewport) * viewMatrix(c) * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
  if (clip.w() <= 0.0) return std::nullopt;
  const double nx = clip.x() / clip.w(), ny = clip.y() / clip.w();
  return ScreenPoint{(nx + 1.0) * 0.5 * viewport.width, (1.0 - ny) * 0.5 * viewport.height,
                     dot(p - c.eye(), c.forward())};
}

Ray pixelRay(const Camera& c, const Viewport& viewport, double x, double y) {
  const double nx = 2.0 * x / viewport.width - 1.0, ny = 1.0 - 2.0 * y / viewport.height;
  const double t = tanHalfFov(c);
  const Vec3 d = c.forward() + c.right() * (nx * t * viewport.aspect()) + c.up() * (ny * t);
  return {c.eye(), normalized(d)};
}

Vec3 dragTarget(const Camera& c, const Viewport& viewport, double x, double y, const Vec3& anchor) {
  const Ray ray = pixelRay(c, viewport, x, y);
  const Vec3 f = c.forward();
  // The ray meets the plane dot(p - anchor, f) = 0 at the parameter below; rays through the
  // window always point into the half-space in front of the eye, so the denominator is > 0.
  const double s = dot(anchor - ray.origin, f) / dot(ray.direction, f);
  return ray.origin + ray.direction * s;
}

Vec3 screenDragToWorld(const Camera& c, double dxPixels, double dyPixels) {
  return c.right() * dxPixels - c.up() * dyPixels;
}

}  // namespace jello::viewer
