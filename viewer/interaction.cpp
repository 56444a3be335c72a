#include "viewer/interaction.h"

#include <array>
#include <cmath>
#include <limits>

namespace jello::viewer {

std::span<const double> pullRadii() {
  static constexpr std::array<double, 6> radii{0.0, 0.15, 0.3,
                                               0.6, 1.2,  std::numeric_limits<double>::infinity()};
  return radii;
}

Eigen::VectorXd pushForce(int numPoints, double mass, const Vec3& accel) {
  Eigen::VectorXd f(3 * numPoints);
  f.segment(0, numPoints).setConstant(mass * accel.x);
  f.segment(numPoints, numPoints).setConstant(mass * accel.y);
  f.segment(2 * numPoints, numPoints).setConstant(mass * accel.z);
  return f;
}

PullSpring pullSpring(int points, double mass, double kElastic, double scale) {
  PullSpring spring;
  spring.stiffness = scale * (kElastic > 0.0 ? kElastic : 100.0);
  spring.damping = 2.0 * std::sqrt(spring.stiffness * mass);
  spring.maxForce = kMaxPullAcceleration * mass * points;
  return spring;
}

Eigen::VectorXd pullForce(const Lattice& lattice, const State& state, int picked,
                          const Vec3& target, double radius, const PullSpring& spring) {
  const int n = lattice.n, count = lattice.numPoints();
  const auto rest = [&](int p) { return lattice.restPosition(p / (n * n), (p / n) % n, p % n); };
  const Vec3 origin = rest(picked);
  const auto weight = [&](int p) {
    if (std::isinf(radius) || p == picked) return 1.0;
    const double d = norm(rest(p) - origin);
    return d < radius ? 1.0 - d / radius : 0.0;
  };
  double weightSum = 0.0;  // a second pass rather than a vector per step
  for (int p = 0; p < count; ++p) weightSum += weight(p);
  Vec3 pull = (target - state.position(picked)) * spring.stiffness;
  const double total = norm(pull) * weightSum;
  if (total > spring.maxForce) pull = pull * (spring.maxForce / total);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * count);
  for (int p = 0; p < count; ++p) {
    const double w = weight(p);
    if (w > 0.0) State::set(f, p, (pull - state.velocity(p) * spring.damping) * w);
  }
  return f;
}

std::optional<int> pickPoint(const Camera& camera, const Viewport& viewport,
                             const SurfaceMesh& mesh, const State& state, double x, double y) {
  const Ray ray = pixelRay(camera, viewport, x, y);
  std::optional<int> best;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& t : mesh.triangles) {
    const Vec3 a = state.position(t[0]), b = state.position(t[1]), c = state.position(t[2]);
    const Vec3 e1 = b - a, e2 = c - a, q = cross(ray.direction, e2);
    const double det = dot(e1, q);
    if (std::abs(det) < 1e-14) continue;  // the ray runs along the triangle
    const Vec3 s = ray.origin - a;
    const double u = dot(s, q) / det;
    if (u < 0.0 || u > 1.0) continue;
    const Vec3 r = cross(s, e1);
    const double v = dot(ray.direction, r) / det;
    if (v < 0.0 || u + v > 1.0) continue;
    const double distance = dot(e2, r) / det;
    if (distance <= 0.0 || distance >= nearest) continue;
    nearest = distance;
    const Vec3 hit = ray.origin + ray.direction * distance;
    best = t[0];
    for (int p : t) {
      if (norm(state.position(p) - hit) < norm(state.position(*best) - hit)) best = p;
    }
  }
  return best;
}

}  // namespace jello::viewer
