// The external force field (worlds/FORMAT.md): forces F (N) on res^3 nodes covering [-2,2]^3,
// node (i,j,k) at -2 + 4*(i,j,k)/(res-1), interpolated trilinearly between nodes. A point
// outside the box takes the value at the nearest point of the box (its position is clamped).
// A field whose nodes are all equal is a constant force and is applied as one (no
// interpolation); an all-zero field is no effect at all (the Model leaves it out).
#pragma once

#include "src/effects/jacobian_blocks.h"
#include "src/world/world.h"

namespace jello {

class FieldForces {
 public:
  explicit FieldForces(ForceField field);

  Vec3 sample(const Vec3& position) const;  // N
  // dF_a/dx_b (N/m), row a, column b: the derivative of the trilinear interpolant inside the
  // cell, zero along an axis where the position is clamped. Not symmetric in general.
  void gradient(const Vec3& position, double out[3][3]) const;
  // Adds the field force at each of the n points (component-major x) to f; the second, at the
  // points [lo, hi) only.
  void accumulate(const double* x, double* f, int n) const { accumulate(x, f, n, 0, n); }
  void accumulate(const double* x, double* f, int n, int lo, int hi) const;
  // Adds gradient() to each point's diagonal block of K (only with out.includeField).
  void addJacobian(const double* x, int n, JacobianBlocks& out) const;

  bool isUniform() const { return uniform_; }
  bool isZero() const { return uniform_ && constant_ == Vec3{}; }

 private:
  ForceField field_;
  bool uniform_ = false;
  Vec3 constant_;
};

}  // namespace jello
