// Elastic springs: Hooke plus damping projected on the spring (src/PHYSICS.md).
//   d = x_q - x_p, l = |d|, w = v_q - v_p
//   f_p = [ k (1 - L0/l) + c (d.w)/l^2 ] d,   f_q = -f_p
//   energy = 1/2 k (l - L0)^2
// Springs come in groups that share a flat index offset, a rest length and constants: group g
// links p -> p + delta for p in [first, first + mask.size()) where mask[p - first] != 0. On the
// lattice every spring offset is one group, so the loop body reads contiguous memory and the
// compiler vectorizes it, square root and division included. The loop is bound by its
// multiply-adds and its loads and stores together, not by the square root and division; a pass
// over chunks of 8 base points that kept their positions and forces in registers across the
// groups, and one with fewer multiply-adds (intrinsics), were both slower (BM_SpringForces;
// solvers/README.md keeps what was tried).
#pragma once

#include <cstddef>
#include <vector>

#include "src/effects/jacobian_blocks.h"
#include "src/world/lattice.h"

namespace jello {

struct SpringGroup {
  SpringKind kind = SpringKind::Structural;
  int delta = 1;             // flat index offset from p to its partner
  int first = 0;             // first base point
  std::vector<double> mask;  // 1 where p -> p + delta is a spring, 0 where it is not
  double rest = 0.0;         // m
  double stiffness = 0.0;    // N/m
  double damping = 0.0;      // N*s/m
  int numSprings = 0;
};

struct Spring {
  int a, b;     // point indices
  double rest;  // m
  SpringKind kind;
  double stiffness;  // N/m
  double damping;    // N*s/m
};

// Groups for every spring of the lattice, all with the same constants.
std::vector<SpringGroup> latticeSpringGroups(const Lattice& lattice, double stiffness,
                                             double damping);

class SpringForces {
 public:
  SpringForces(std::vector<SpringGroup> groups, int numPoints);

  // Adds the spring forces (N) of state (x, v) to f. All arrays component-major, 3n. Keeps no
  // state: threads may evaluate one SpringForces at once. From kParallelMinPoints points up
  // the work is split over parallelThreads() threads (src/base/parallel.h).
  void accumulate(const double* x, const double* v, double* f) const;
  double energy(const double* x) const;  // J; split over threads as accumulate is
  // Adds the springs' blocks of K and D at positions x (the forces are linear in v, so D does
  // not depend on it), u the unit vector along a spring, P = u u^T, alpha = 1 - L0/l:
  //   Ke = -k [ P + alpha (I - P) ],  De = -c P   on (a,a) and (b,b); -Ke, -De on (a,b), (b,a).
  // With out.clampCompression, alpha < 0 (compression) is replaced by 0 and counted. The
  // x-derivative of spring damping (not symmetric) is left out, as Baraff & Witkin do.
  void addJacobian(const double* x, JacobianBlocks& out) const;

  // The springs whose base point is in [lo, hi) (both ends' forces), on the calling thread:
  // for a caller that splits the work itself (Model), as accumulate does, by runOverPointBlocks
  // with reach() and the threads accumulate would use, threads().
  void accumulateRange(const double* x, const double* v, double* f, std::ptrdiff_t lo,
                       std::ptrdiff_t hi) const;
  // The largest offset from a spring's base point to its partner.
  int reach() const { return maxDelta_; }
  // The threads accumulate splits its work over: parallelThreads() from kParallelMinPoints
  // points up, else 1.
  int threads() const;

  int numSprings() const { return numSprings_; }
  const std::vector<SpringGroup>& groups() const { return groups_; }
  // The same springs as a plain list (Jacobian assembly, drawing, tests).
  std::vector<Spring> springs() const;

 private:
  // The energy of part `part` of `parts` of each group's springs.
  double energyRange(const double* x, int part, int parts) const;

  std::vector<SpringGroup> groups_;
  int n_;
  int numSprings_ = 0;
  int maxDelta_ = 0;  // the largest offset of a spring's partner
};

}  // namespace jello
