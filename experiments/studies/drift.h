// Long-run drift: an undamped free cube (the spinning stiff cube, springs k, no damping, nothing
// touched) run for a long time by each integrator. Its equations keep the total energy and the
// angular momentum exactly, so whatever changes is the method's: RK4's slow loss, symplectic
// Euler's and midpoint's bounded swing, backward Euler's and BDF2's damping, forward Euler's
// growth. Part of jello-work-precision (its NAME_drift.csv and NAME_drift_summary.csv).
#pragma once

#include <string>
#include <vector>

#include "experiments/studies/csv_table.h"
#include "src/world/integrator_table.h"
#include "src/world/world.h"

namespace jello::experiments {

struct DriftSetup {
  double k = 1e3;                 // N/m
  double time = 100.0;            // s
  double interval = 0.1;          // s between samples
  double implicitDt = 0.01;       // s, every implicit integrator
  double explicitFraction = 0.5;  // explicit methods at this fraction of symplectic's/RK4's limit
};

struct DriftRun {
  IntegratorKind kind;
  double dt;     // s
  double hwMax;  // dt times the scene's w_max at the start
};

// The scene: spinningStiffCube(k, 0) (stability_analysis.h).
World driftScene(const DriftSetup& setup);

// The runs: forward Euler (at symplectic Euler's step: it is unstable at every step without
// damping), symplectic Euler and RK4 at explicitFraction of their predicted limits, and the
// implicit integrators at implicitDt (`quick`: symplectic, RK4, implicit and midpoint only).
std::vector<DriftRun> driftPlan(const World& scene, const DriftSetup& setup, bool quick);

// One row per sample: integrator, dt_s, t_s, energy_J, energy_ratio (E/E0),
// angular_momentum_error (|L - L0| / |L0|).
CsvTable driftSeriesTable();
// One row per run: integrator, dt_s, h_w_max, steps, wall_time_s, energy_ratio_end,
// energy_deviation_max_first_half and _second_half (max |E/E0 - 1| over each half of the run:
// a bounded swing has about the same in both, a drift more in the second),
// angular_momentum_error_max, outcome ("ok", "diverged", or "failed": a solver gave up),
// diverged_at_s (the time of the last sane state, or of the failure).
CsvTable driftSummaryTable();

// Runs `run` over setup.time on `scene`, adding its samples to `series` and its summary to
// `summary`. A divergence ends the run and is recorded, not thrown.
void runDrift(const World& scene, const DriftRun& run, const DriftSetup& setup, CsvTable& series,
              CsvTable& summary);

}  // namespace jello::experiments
