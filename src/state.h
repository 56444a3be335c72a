// The simulated state: time t and flat position/velocity vectors of 3n entries.
//
// Layout is component-major: x = [x_0 .. x_{n-1}, y_0 .. y_{n-1}, z_0 .. z_{n-1}], so the spring
// loop reads contiguous runs and vectorizes. Point p's y is x[n + p]. Jacobians use the same
// ordering (row c*n + p is component c of point p).
#pragma once

#include <Eigen/Core>

#include "src/base/vec3.h"
#include "src/world/world.h"

namespace jello {

struct State {
  double t = 0.0;     // s
  Eigen::VectorXd x;  // m, 3n
  Eigen::VectorXd v;  // m/s, 3n

  int numPoints() const { return static_cast<int>(x.size() / 3); }
  Vec3 position(int p) const { return at(x, p); }
  Vec3 velocity(int p) const { return at(v, p); }
  // The mean of the points' positions: the centre of mass (every point has the same mass).
  Vec3 centroid() const {
    const Eigen::Index n = x.size() / 3;
    if (n == 0) return {};
    return {x.head(n).mean(), x.segment(n, n).mean(), x.tail(n).mean()};
  }

  static Vec3 at(const Eigen::VectorXd& a, int p) {
    const Eigen::Index n = a.size() / 3;
    return {a[p], a[n + p], a[2 * n + p]};
  }
  static void set(Eigen::VectorXd& a, int p, const Vec3& value) {
    const Eigen::Index n = a.size() / 3;
    a[p] = value.x;
    a[n + p] = value.y;
    a[2 * n + p] = value.z;
  }
};

// The world's initial positions and velocities at t = 0.
State initialState(const World& world);

// Writes the state's positions and velocities back into the world (for saving).
void storeState(const State& state, World& world);

}  // namespace jello
