// The fastest mode of a scene: linearized at a state, the modes have w_j^2 = eig(-K/m) (uniform
// point mass m, so M^-1/2 (-K) M^-1/2 = -K/m; K includes contact springs in touch). Spectra's
// Lanczos solver finds the largest, w_max: a general eigen-solver is thrown off by the six rigid
// modes at 0. Used by the stability analysis (experiments/studies) and jello-sim's cvode warning.
#pragma once

#include "src/model.h"
#include "src/state.h"

namespace jello {

// sqrt of the largest eigenvalue of -K/m at `state` (rad/s); K is the exact (unclamped) spring
// and contact Jacobian. Throws std::runtime_error when Spectra does not converge.
double maxAngularFrequency(const Model& model, const State& state);

}  // namespace jello
