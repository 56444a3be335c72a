// The linear theory of an integrator's artificial damping, per mode. An undamped scene near its
// rest shape is, to first order, a sum of independent oscillators x_j'' = -w_j^2 x_j (the modes
// of -K/m at rest, K the spring Jacobian of the lattice at rest, every point of mass m). Each
// implicit integrator applied to the whole scene is, to the same order, its own linear map
// applied to every oscillator:
//   implicit, implicit-linear, projective  backward Euler: (I - hA) y1 = y0, energy factor per
//                                          step 1/(1 + h^2 w^2), rate ln(1 + h^2 w^2)/h
//   bdf2                                   (I - 2/3 h A) y2 = 4/3 y1 - 1/3 y0 after one backward-
//                                          Euler step
//   midpoint, newmark                      (I - h/2 A) y1 = (I + h/2 A) y0: energy kept exactly
// with y = (x_j, v_j) and A = [[0, 1], [-w_j^2, 0]]. The prediction for the scene is the sum of
// the modes' energies; what the nonlinear simulation measures differs by the springs'
// nonlinearity (small at the 5% stretch of the damping scene).
#pragma once

#include <Eigen/Core>

#include "src/world/integrator_table.h"
#include "src/world/world.h"

namespace jello::experiments {

struct ModalDecomposition {
  double mass = 0.0;         // kg per point
  Eigen::VectorXd omega;     // rad/s, every mode (3n; the six rigid modes near 0)
  Eigen::VectorXd position;  // m, the initial displacement from the rest lattice on each mode
  Eigen::VectorXd velocity;  // m/s, the initial velocity on each mode
  double energy() const;     // J, the linearized total energy
};

// The world's initial state against its lattice at rest with the same centre of mass, on the
// modes of -K/m there (K with whatever contact the rest lattice is in; a dense symmetric
// eigen-solve of 3N^3 unknowns). Throws std::invalid_argument above N = 10 (minutes of solve).
ModalDecomposition decomposeOnRestModes(const World& world);

// True for the integrators the theory covers (implicit, implicit-linear, projective, bdf2,
// midpoint, newmark).
bool hasModalTheory(IntegratorKind kind);

// The linearized energy after `steps` steps of dt by `kind` from `modes` (hasModalTheory(kind)).
double predictedEnergy(const ModalDecomposition& modes, IntegratorKind kind, double dt, long steps);

}  // namespace jello::experiments
