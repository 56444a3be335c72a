// The stability experiment's physics: the fastest mode of a scene, each integrator's predicted
// largest stable time step, the tested definition of "blew up", and the bisection that
// measures the threshold.
//
// Linearized at the start state, the modes have w_j^2 = eig(-K/m) (uniform point mass m, so
// M^-1/2 (-K) M^-1/2 = -K/m; K includes contact springs in touch). Spectra's Lanczos solver
// finds the largest, w_max: a general eigen-solver is thrown off by the six rigid modes at 0.
// Spring damping c = r k gives every mode the damping ratio zeta = r w / 2 (src/PHYSICS.md): the
// mode's eigenvalues are lambda = w (-zeta +- i sqrt(1 - zeta^2)) (real when zeta > 1). A
// method is stable at h when every mode w in (0, w_max] has amplification spectral radius <= 1:
//   euler      R = 1 + z                                    (h <= r exactly when zeta <= 1)
//   rk4        R = 1 + z + z^2/2 + z^3/6 + z^4/24           (h w <= 2 sqrt 2 undamped)
//   symplectic the 2x2 map v' = v + h a(x, v), x' = x + h v' (h w < 2 undamped)
// with z = h lambda. implicit (backward Euler) and cvode (adaptive BDF) have no such limit.
#pragma once

#include <limits>
#include <string>
#include <string_view>

#include "solvers/solver_options.h"
#include "solvers/system/modes.h"
#include "src/model.h"
#include "src/world/integrator_table.h"
#include "src/world/world.h"

namespace jello::experiments {

// maxAngularFrequency (solvers/system/modes.h), as the experiments call it.
using jello::maxAngularFrequency;

// predictedThreshold (solvers/system/modes.h), as the experiments call it.
using jello::predictedThreshold;

// The standard scenes, spring damping c = r k:
//   "free": the cube at rest with its far corner pulled out by one spacing, in the middle of the
//           box, touching nothing (the walls are never reached);
//   "wall": the cube pressed onto the floor by a uniform load that sinks its bottom layer 1% of
//           a spacing into it, contact springs contactRatio times stiffer than the lattice's
//           (kCollision = contactRatio k, dCollision = r kCollision); settled to its loaded
//           equilibrium, then every point moved by up to 10^-4 of a spacing. The contact mode
//           sets w_max, and the cube stays in contact.
World stabilityScene(std::string_view scene, double k, double dampingRatio,
                     double contactRatio = 20.0);

// The stiff cube of work-precision and the drift run: stretched 5% along x and spinning at
// `spin` rad/s about z (scene_builder.h's vibratingStiffCube), springs k, damping c, centred in
// the box (walls 1.5 m away, never reached), no field, no plane.
World spinningStiffCube(double k, double damping, double spin = 2.0);

// The stability experiment's envelope: the first 64 steps (its results were measured so).
inline constexpr long kBlowUpEnvelopeSteps = 64;

// "Blew up": within the run, a step produced a non-finite or far state (the simulation's
// divergence check, bound 100 m) or the total energy (kinetic + spring + contact, minus the work
// the force field has done) rose above energyFactor times its envelope: for the explicit methods
// the largest energy of the first kBlowUpEnvelopeSteps steps, for the implicit ones the start's
// (solvers/simulation.h; the simulation applies the same rule, its envelope over 16 steps: it
// must judge runs of a few dozen steps, these last thousands). Measured against the envelope
// rather than the start, a bounded oscillation cannot fire it: symplectic Euler's energy swings
// by 1/(1 - h w/2) near h w = 2 without growing (tested at h w = 1.9 over 10 s; at 2.1 it
// fires). The run lasts `time` simulated seconds, and explicit
// methods at least `minSteps` steps: just past its limit an unstable mode grows by a factor
// barely above 1 per step, which a 0.2 s window of 20 steps (RK4 at k = 10) cannot see.
struct BlowUpRule {
  // The simulated times and largest steps a study can run: every run's step count (time / dt
  // with dt down to kMinDtMax) fits, and no step is subnormal (jello-stability's --time and
  // --dt-max, the Python stability_threshold's time and dt_max).
  static constexpr double kMinTime = 1e-4, kMaxTime = 1e3;    // s
  static constexpr double kMinDtMax = 1e-9, kMaxDtMax = 1.0;  // s
  double time = 0.2;                                          // s
  double energyFactor = 10.0;
  long minSteps = 2000;  // explicit methods (euler, symplectic, rk4) only
};

struct Trial {
  bool blewUp = false;
  std::string reason;
  long steps = 0;
};
Trial runTrial(const World& world, IntegratorKind kind, double dt, const BlowUpRule& rule,
               const SolverOptions& options = {});

struct Threshold {
  double stable = 0.0;  // s, largest dt seen stable (0: none down to dtMin)
  double unstable = std::numeric_limits<double>::infinity();  // s, smallest seen to blow up
  int trials = 0;
  bool stableToMax() const { return std::isinf(unstable); }
};
// First tries dtMax; if it blows up, brackets downward from `guess` by factors of 2 (not below
// dtMin), then bisects geometrically until unstable/stable <= 1 + relativeTolerance.
Threshold findThreshold(const World& world, IntegratorKind kind, const BlowUpRule& rule,
                        double guess, double dtMax, double relativeTolerance = 0.02,
                        double dtMin = 1e-8, const SolverOptions& options = {});

}  // namespace jello::experiments
