// Where the effects write their derivatives: K = df/dx (N/m) and D = df/dv (N*s/m), 3n x 3n in
// the state's component-major ordering (src/PHYSICS.md, "Jacobians"). Each effect adds its
// terms next to its force and energy (addJacobian beside accumulate); the sparse matrices
// themselves belong to the solver layer (solvers/system/implicit_system.h), which hands over
//   diagK, diagD   the 3x3 diagonal block of every point, row-major, 9 per point, zeroed before
//                  the effects add to them (springs, walls, plane, sphere, field all land here),
//   K, D           the matrices' value arrays, and springSlots (18 per spring, in the order of
//                  SpringForces::springs()): where the (a,b) and (b,a) blocks of each spring
//                  live in them. Only springs have off-diagonal blocks; each assigns its own.
#pragma once

namespace jello {

struct JacobianBlocks {
  double* diagK = nullptr;
  double* diagD = nullptr;
  double* K = nullptr;
  double* D = nullptr;
  const int* springSlots = nullptr;
  // Project each element Hessian onto semidefinite matrices: a compressed spring's transverse
  // term and the sphere's curvature term are dropped (the clamp, src/PHYSICS.md).
  bool clampCompression = true;
  // The field's gradient (not symmetric: not for Cholesky).
  bool includeField = false;
  // The springs' terms (off: the other effects' diagonal blocks only, for a caller that takes
  // the springs' blocks straight from the positions, solvers/system/system_operator.h).
  bool includeSprings = true;
  // The velocities (3n) friction's D and the smooth law's damping term of K are evaluated at;
  // none: both are left out.
  const double* velocities = nullptr;
  // Friction's D blocks go here (9 per point) instead of diagD when set (the assembler keeps
  // them apart for Newton's merit, then adds them to D).
  double* diagFriction = nullptr;
  long clamps = 0;  // out: springs clamped in this assembly
};

}  // namespace jello
