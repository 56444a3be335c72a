// The product y = A p with the implicit system's matrix A = M - a D - b K, taken without the
// sparse matrix: A's 3x3 block of every spring (a, b) (symmetric, as K's and D's are) and of
// every point's diagonal are gathered once per matrix into arrays laid out like the spring
// groups (src/effects/spring_forces.h), and the product runs over the groups in unit-stride loops
// that vectorize, as the force kernel does. Per spring it reads 6 coefficients and does 2 3x3
// products: a third of the memory a CSR product moves for the same matrix (each spring's block
// appears twice there, with its column indices).
//
// The effects' other terms (contact, the field's gradient when it is included) sit on the
// points' diagonal blocks, so every matrix the implicit system forms is covered.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "solvers/linalg/linear_operator.h"
#include "solvers/system/jacobian.h"

namespace jello {

class SystemOperator final : public LinearOperator {
 public:
  // The springs' groups of `springs`, over numPoints points.
  SystemOperator(const SpringForces& springs, int numPoints);

  // Takes A's values at the slots JacobianAssembler gives (diagSlots: 9 per point,
  // springSlots: 18 per spring, in the order of SpringForces::springs()).
  void gather(const SparseMatrix& A, const std::vector<int>& diagSlots,
              const std::vector<int>& springSlots);

  // A = mass I - a D - b K straight from the springs at positions x (3n), without the sparse
  // matrices: each spring's (a, b) block is -a c P - b k (P + alpha (I - P)) (P = u u^T,
  // alpha = 1 - rest/length, 0 where `clamp` projects a compressed spring), each point's diagonal
  // block mass I - a diagD - b diagK (9 per point, row-major: the other effects' terms,
  // JacobianAssembler::assemble without the springs) minus its springs' blocks. The same values
  // gather() takes from the assembled A, in one vectorized pass; returns the springs clamped.
  long fill(const double* x, double mass, double a, double b, bool clamp, const double* diagK,
            const double* diagD);

  // The springs' part of v^T D v at positions x (both 3n): -sum c (u . (v_b - v_a))^2.
  double springDampingQuadratic(const double* x, const double* v) const;

  // y = A p, both 3n component-major; y is overwritten, and must not alias p. Split over
  // threads from kParallelMinPoints points (src/base/parallel.h), as the spring forces are
  // (round-off apart from the serial sum); BM_Threads/product measures one thread against two.
  void apply(const double* p, double* y) const override;

  // Each point's diagonal block of A as 6 arrays of n (xx, xy, xz, yy, yz, zz): block-Jacobi.
  std::array<const double*, 6> diagonalBlocks() const override {
    return {diag_[0].data(), diag_[1].data(), diag_[2].data(),
            diag_[3].data(), diag_[4].data(), diag_[5].data()};
  }
  int numPoints() const { return n_; }

 private:
  struct Group {
    std::ptrdiff_t first = 0, count = 0, delta = 0;
    double rest = 0.0, stiffness = 0.0, damping = 0.0;
    std::vector<double> mask;              // 1 where the slot is a spring
    std::array<std::vector<double>, 6> c;  // the spring's block of A, upper triangle
  };
  // y = A p's terms of the points' own blocks in [setLo, setHi), which it sets first, then of
  // the springs with a base point in [lo, hi) (src/base/parallel.h, runOverPointBlocks).
  void applyRange(const double* p, double* y, std::ptrdiff_t setLo, std::ptrdiff_t setHi,
                  std::ptrdiff_t lo, std::ptrdiff_t hi) const;
  std::vector<Group> groups_;
  std::array<std::vector<double>, 6> diag_;
  int n_ = 0;
  std::ptrdiff_t maxDelta_ = 0;  // the largest offset of a spring's partner
};

}  // namespace jello
