// LatticeCoarseSpace (solvers/system/lattice_coarse_space.h): its hat functions interpolate
// linear fields exactly, its correction is the Galerkin one (the residual left orthogonal to the
// coarse space), and with a node at every point it solves the system outright.
#include "solvers/system/lattice_coarse_space.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "solvers/system/spring_laplacian.h"
#include "src/model.h"
#include "src/world/lattice.h"
#include "src/world/scene_builder.h"
#include "tests/test_support.h"

namespace jello {
namespace {

// M/h^2 + L of jello.w at `resolution` points per edge, h = 0.01: projective's matrix.
SparseMatrix projectiveMatrix(int resolution) {
  const Model model(resampleCube(test::loadWorld("jello.w"), resolution));
  SparseMatrix S;
  SpringLaplacian(model).form(model.mass() / 1e-4, 0.0, 1.0, nullptr, S);
  return S;
}

TEST(LatticeCoarseSpace, InterpolatesTrilinearFieldsExactly) {
  const int resolution = 7, nodes = 3;
  const LatticeCoarseSpace space(resolution, nodes);
  ASSERT_EQ(space.size(), 27);
  // f(i, j, k) = 1 + 2 i - 3 j + 0.5 k in lattice index units, at the coarse nodes (a node a
  // spans (resolution - 1) / (nodes - 1) points).
  const double span = double(resolution - 1) / (nodes - 1);
  // Linear in each index, with products: trilinear interpolation reproduces it in every cell,
  // and a mix-up of the axes would not.
  const auto f = [](double i, double j, double k) {
    return 1.0 + 2.0 * i - 3.0 * j + 0.5 * k + 0.25 * i * j - 0.125 * j * k + 0.0625 * i * j * k;
  };
  Eigen::VectorXd coarse(27);
  for (int a = 0; a < nodes; ++a)
    for (int b = 0; b < nodes; ++b)
      for (int c = 0; c < nodes; ++c)
        coarse[(a * nodes + b) * nodes + c] = f(a * span, b * span, c * span);
  const Lattice lattice{resolution};
  Eigen::VectorXd fine = Eigen::VectorXd::Zero(lattice.numPoints());
  space.prolong(coarse.data(), fine.data());
  for (int i = 0; i < resolution; ++i)
    for (int j = 0; j < resolution; ++j)
      for (int k = 0; k < resolution; ++k) {
        EXPECT_NEAR(fine[lattice.index(i, j, k)], f(i, j, k), 1e-12);
      }
}

// Contact weights on a random tenth of the points; a random right-hand side.
struct CorrectionCase {
  int resolution;
  SparseMatrix S;
  Eigen::VectorXd w, r;
  explicit CorrectionCase(int res) : resolution(res), S(projectiveMatrix(res)) {
    const int n = static_cast<int>(S.rows());
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    w.setZero(n);
    r.resize(n);
    for (int p = 0; p < n; ++p) {
      if (u(rng) < 0.1) w[p] = 400.0 + 2000.0 * u(rng);
      r[p] = u(rng) - 0.5;
    }
  }
  // delta = -S^-1 r (the factor without the weights), then corrected on `nodes` nodes per edge.
  Eigen::VectorXd corrected(int nodes) const {
    LatticeCoarseSpace space(resolution, nodes);
    space.setBase(S);
    Eigen::VectorXd delta = -Eigen::MatrixXd(S).llt().solve(r);
    EXPECT_TRUE(space.correct(w, w.data(), delta.data()).ok);
    return delta;
  }
  Eigen::VectorXd residual(const Eigen::VectorXd& delta) const {
    return S * delta + w.cwiseProduct(delta) + r;
  }
};

TEST(LatticeCoarseSpace, WithANodeAtEveryPointTheCorrectionSolvesTheSystem) {
  const CorrectionCase c(5);
  const Eigen::VectorXd delta = c.corrected(5);  // P = I
  EXPECT_LT(c.residual(delta).norm(), 1e-9 * c.r.norm());
}

TEST(LatticeCoarseSpace, TheCorrectionLeavesTheResidualOrthogonalToTheCoarseSpace) {
  const CorrectionCase c(7);
  const int nodes = 3;
  const Eigen::VectorXd before = -Eigen::MatrixXd(c.S).llt().solve(c.r);
  const Eigen::VectorXd delta = c.corrected(nodes);
  const Eigen::VectorXd res = c.residual(delta);
  const LatticeCoarseSpace space(7, nodes);
  const int n = static_cast<int>(c.r.size());
  double largest = 0.0;
  for (int j = 0; j < space.size(); ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(space.size()), column = Eigen::VectorXd::Zero(n);
    e[j] = 1.0;
    space.prolong(e.data(), column.data());
    largest = std::max(largest, std::abs(column.dot(res)));
  }
  EXPECT_LT(largest, 1e-9 * c.r.norm());
  // And the energy (the quadratic the solve minimizes) went down.
  const auto energy = [&](const Eigen::VectorXd& x) {
    return 0.5 * x.dot(c.S * x + c.w.cwiseProduct(x)) + c.r.dot(x);
  };
  EXPECT_LT(energy(delta), energy(before));
}

}  // namespace
}  // namespace jello
