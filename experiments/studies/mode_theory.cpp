#include "experiments/studies/mode_theory.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

#include "solvers/system/jacobian.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/lattice.h"

namespace jello::experiments {

double ModalDecomposition::energy() const {
  return 0.5 * mass * (velocity.squaredNorm() + (omega.array() * position.array()).square().sum());
}

ModalDecomposition decomposeOnRestModes(const World& world) {
  const int n = world.cubeResolution;
  if (n > 10) throw std::invalid_argument("modal theory: N = " + std::to_string(n) + " > 10");
  const State start = initialState(world);
  const Lattice lattice{n};
  // The rest lattice, moved to the start's centre of mass (a rigid translation: a zero mode).
  State rest = start;
  Vec3 centre{0, 0, 0}, restCentre{0, 0, 0};
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const int p = lattice.index(i, j, k);
        State::set(rest.x, p, lattice.restPosition(i, j, k));
        centre += start.position(p);
        restCentre += lattice.restPosition(i, j, k);
      }
    }
  }
  const Vec3 shift = (centre - restCentre) * (1.0 / lattice.numPoints());
  for (int p = 0; p < lattice.numPoints(); ++p) State::set(rest.x, p, rest.position(p) + shift);

  const Model model(world);
  JacobianAssembler assembler(model);
  assembler.assemble(rest.x.data(), {.clampCompression = false});
  const Eigen::MatrixXd stiffness = -Eigen::MatrixXd(assembler.K()) / world.mass;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(stiffness);
  if (eigen.info() != Eigen::Success) {
    throw std::runtime_error("modal theory: the eigen-solver did not converge");
  }
  ModalDecomposition modes;
  modes.mass = world.mass;
  // Round-off leaves the rigid modes' eigenvalues slightly negative.
  modes.omega = eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  modes.position = eigen.eigenvectors().transpose() * (start.x - rest.x);
  modes.velocity = eigen.eigenvectors().transpose() * start.v;
  return modes;
}

bool hasModalTheory(IntegratorKind kind) {
  return isAStable(linearModel(kind));
}

double predictedEnergy(const ModalDecomposition& modes, IntegratorKind kind, double dt,
                       long steps) {
  if (!hasModalTheory(kind)) {
    throw std::invalid_argument("modal theory: no linear map for " +
                                std::string(integratorName(kind)));
  }
  const LinearModel model = linearModel(kind);
  const bool bdf2 = model == LinearModel::Bdf2;
  const bool trapezoidal = model == LinearModel::Trapezoidal;
  double energy = 0.0;
  for (Eigen::Index j = 0; j < modes.omega.size(); ++j) {
    const double w = modes.omega[j];
    Eigen::Matrix2d a;
    a << 0.0, 1.0, -w * w, 0.0;
    const Eigen::Matrix2d identity = Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d backward = (identity - dt * a).inverse();
    const Eigen::Matrix2d bdf = (identity - (2.0 / 3.0) * dt * a).inverse();
    const Eigen::Matrix2d trapezoid =
        (identity - 0.5 * dt * a).inverse() * (identity + 0.5 * dt * a);
    Eigen::Vector2d previous, y{modes.position[j], modes.velocity[j]};
    for (long s = 0; s < steps; ++s) {
      Eigen::Vector2d next;
      if (trapezoidal) {
        next = trapezoid * y;
      } else if (bdf2 && s > 0) {
        next = bdf * ((4.0 / 3.0) * y - (1.0 / 3.0) * previous);
      } else {
        next = backward * y;
      }
      previous = y;
      y = next;
    }
    energy += 0.5 * modes.mass * (y[1] * y[1] + w * w * y[0] * y[0]);
  }
  return energy;
}

}  // namespace jello::experiments
