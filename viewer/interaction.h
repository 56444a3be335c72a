// What the mouse does to the cube, as forces the simulation adds (Model::setUserForce).
//   push: every point gets m a, a = kPushPerPixel * (drag in pixels mapped onto the screen's
//         plane): the whole cube accelerates in the dragged direction.
//   pull: a picked surface point p is pulled towards the cursor's point in the plane through p
//         facing the camera: f_i = k_pull w_i (target - x_p), with weights falling off with
//         rest distance d_i from p: w_i = 1 - d_i / R inside the radius R, 0 outside; R = 0
//         pulls p alone, an unbounded R pulls every point with w = 1. The spring is damped
//         and its force bounded (PullSpring).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "src/state.h"
#include "src/world/lattice.h"
#include "viewer/camera.h"
#include "viewer/surface.h"

namespace jello::viewer {

inline constexpr double kPushPerPixel = 0.2;  // m/s^2 of the cube's acceleration per pixel

// Pull radii the `[` and `]` keys step through (m, rest distance); the last one is the whole
// cube at full weight.
std::span<const double> pullRadii();

// Uniform force (N, 3n) that gives every point of mass `mass` the acceleration `accel`.
Eigen::VectorXd pushForce(int numPoints, double mass, const Vec3& accel);

// The pull's spring to the cursor: stiffness k_pull (N/m), damping c (N s/m per unit weight)
// and a bound on the spring's total force (N), so that no drag can fling the cube.
struct PullSpring {
  double stiffness = 0.0;
  double damping = 0.0;
  double maxForce = std::numeric_limits<double>::infinity();
};
inline constexpr double kMaxPullAcceleration = 30.0;  // m/s^2 the pull gives the whole cube at most
// The viewer's pull for a cube of `points` points of mass `mass` and spring constant k: k_pull =
// scale * k (100 N/m when k = 0), critically damped per point (c = 2 sqrt(k_pull m)), its total
// force at most kMaxPullAcceleration times the cube's mass.
PullSpring pullSpring(int points, double mass, double kElastic, double scale = 1.0);

// Pull force (N, 3n) as above, damped and bounded: f_i = w_i (s k_pull (target - x_p) - c v_i),
// s <= 1 scaling the spring part so that sum_i w_i |s k_pull (target - x_p)| <= maxForce.
Eigen::VectorXd pullForce(const Lattice& lattice, const State& state, int picked,
                          const Vec3& target, double radius, const PullSpring& spring);

// The surface point under pixel (x, y): the ray through the pixel hits the surface's nearest
// triangle (Moller-Trumbore), and of its three corners the one closest to the hit is picked.
// Nothing when the ray misses the cube.
std::optional<int> pickPoint(const Camera& camera, const Viewport& viewport,
                             const SurfaceMesh& mesh, const State& state, double x, double y);

}  // namespace jello::viewer
