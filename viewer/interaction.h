// What the mouse does to the cube, as forces the simulation adds (Model::setUserForce).
//   push: every point gets m a, a = kPushPerPixel * (drag in pixels mapped onto the screen's
//         plane): the whole cube accelerates in the dragged direction.
//   pull: a picked surface point p is pulled towards the cursor's point in the plane through p
//         facing the camera: f_i = k_pull w_i (target - x_p), with weights falling off with
//         rest distance d_i from p: w_i = 1 - d_i / R inside the radius R, 0 outside; R = 0
//         pulls p alone, an unbounded R pulls every point with w = 1.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "src/lattice.h"
#include "src/state.h"
#include "viewer/camera.h"
#include "viewer/surface.h"

namespace jello::viewer {

inline constexpr double kPushPerPixel = 0.2;  // m/s^2 of the cube's acceleration per pixel

// Pull radii the `[` and `]` keys step through (m, rest distance); the last one is the whole
// cube at full weight.
std::span<const double> pullRadii();

// Uniform force (N, 3n) that gives every point of mass `mass` the acceleration `accel`.
Eigen::VectorXd pushForce(int numPoints, double mass, const Vec3& accel);

// Pull force (N, 3n) as above. `stiffness` is k_pull (N/m).
Eigen::VectorXd pullForce(const Lattice& lattice, const State& state, int picked,
                          const Vec3& target, double radius, double stiffness);

// The surface point under pixel (x, y): the ray through the pixel hits the surface's nearest
// triangle (Moller-Trumbore), and of its three corners the one closest to the hit is picked.
// Nothing when the ray misses the cube.
std::optional<int> pickPoint(const Camera& camera, const Viewport& viewport,
                             const SurfaceMesh& mesh, const State& state, double x, double y);

}  // namespace jello::viewer
