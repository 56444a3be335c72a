// A symmetric 3n x 3n matrix known by its product, for CG: y = A p, and each point's 3x3
// diagonal block (for block-Jacobi). solvers/system/system_operator.h takes the product through
// the spring kernels, without the sparse matrix.
#pragma once

#include <array>

namespace jello {

class LinearOperator {
 public:
  virtual ~LinearOperator() = default;
  // y = A p, both 3n component-major; y is overwritten and must not alias p.
  virtual void apply(const double* p, double* y) const = 0;
  // Each point's diagonal block of A as 6 arrays of n (xx, xy, xz, yy, yz, zz).
  virtual std::array<const double*, 6> diagonalBlocks() const = 0;
};

}  // namespace jello
