// The fastest mode of a scene: linearized at a state, the modes have w_j^2 = eig(-K/m) (uniform
// point mass m, so M^-1/2 (-K) M^-1/2 = -K/m; K includes contact springs in touch). Spectra's
// Lanczos solver finds the largest, w_max: a general eigen-solver is thrown off by the six rigid
// modes at 0; the linear stability limit of each integrator follows from it. Used by the
// stability analysis (experiments/studies), jello-sim's cvode warning and the viewer's compare
// mode (each explicit pane at 0.9 of its limit).
#pragma once

#include <optional>

#include "src/model.h"
#include "src/state.h"
#include "src/world/integrator_table.h"

namespace jello {

// sqrt of the largest eigenvalue of -K/m at `state` (rad/s); K is the exact (unclamped) spring
// and contact Jacobian. Throws std::runtime_error when Spectra does not converge.
double maxAngularFrequency(const Model& model, const State& state);
// The same mode with its shape: w_max and the unit eigenvector (3n: x, y, z blocks).
struct FastestMode {
  double wMax = 0.0;  // rad/s
  Eigen::VectorXd shape;
};
FastestMode fastestMode(const Model& model, const State& state);

// The largest h at which `kind` is stable on every mode up to wMax with damping ratio
// r * w / 2 (r = c/k in s); 0 when never stable, +infinity for the implicit methods and cvode
// (A-stable on the linear equation; nonlinear springs can still make them blow up, measured).
double predictedThreshold(IntegratorKind kind, double wMax, double dampingRatio);

// CVODE keeps its error at rtol on every mode the scene excites, so a lightly damped stiff mode
// is followed, not stepped over: its steps settle at h w_max of about kCvodeStepTimesWmax
// (scripts/cvode-stiff.py measured 0.07-0.16 on jello.w at k = 1e4 .. 1e7, lowest at the
// stiffest; experiments/results/cvode_stiff.csv).
inline constexpr double kCvodeStepTimesWmax = 0.07;
inline constexpr double kCvodeStepsWorthAWarning = 2e5;
struct CvodeCostEstimate {
  double wMax = 0.0;          // rad/s
  double dampingRatio = 0.0;  // of the fastest mode, d w_max / 2k
  double steps = 0.0;         // internal steps for the simulated time
};
// The estimate for `simulated` seconds from `state` when it exceeds kCvodeStepsWorthAWarning
// steps with the fastest mode underdamped and the start not at rest; nothing otherwise (or when
// w_max cannot be computed).
std::optional<CvodeCostEstimate> cvodeCostWarning(const Model& model, const State& state,
                                                  double simulated, double kElastic,
                                                  double dElastic);

}  // namespace jello
