// What the benchmark files share: jello.w at N^3 and the converged Newton methods' fastest
// configuration (benchmarks_implicit.cpp, where it is measured and described).
#pragma once

#include "solvers/solver_options.h"
#include "src/world/world.h"

namespace jello::bench {

// worlds/jello.w resampled to N^3 points.
World jelloAt(int n);
// CG preconditioned by the projective matrix after Chebyshev-accelerated seeds, Newton on the
// exact Jacobian clamped on demand, refactored at every iteration.
SolverOptions fastNewton();

}  // namespace jello::bench
