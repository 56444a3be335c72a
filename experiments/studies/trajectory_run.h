// A timed run of one integrator over a window, sampled every interval and compared with a
// reference trajectory: jello-work-precision's measurement.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "solvers/integrator.h"
#include "src/model.h"
#include "src/state.h"
#include "src/world/world.h"

namespace jello::experiments {

using Clock = std::chrono::steady_clock;
inline double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// States at t_k = k * interval, k = 0 .. K; a reference also keeps each state's total energy
// and angular momentum (measure()), computed once rather than by every run compared with it.
struct Trajectory {
  double interval = 0.0;
  std::vector<State> states;
  std::vector<double> energy;         // J
  std::vector<Vec3> angularMomentum;  // kg m^2/s
  void measure(const Model& model);
};

// The errors of a run against the reference over the whole window, at every sample.
struct Errors {
  double positionMax = 0.0;         // m, max over samples and points of |x - x_ref|
  double positionRms = 0.0;         // m, RMS over samples of the max over points
  double energyMax = 0.0;           // max over samples of |E - E_ref| / E_ref(0)
  double angularMomentumMax = 0.0;  // max over samples of |L - L_ref| / max |L_ref|
};

class ErrorMeter {
 public:
  // `reference` has been measured (Trajectory::measure) on the same scene.
  ErrorMeter(const Model& model, const Trajectory& reference);
  void sample(std::size_t k, const State& s);  // the state at reference sample k
  Errors result() const;

 private:
  const Model& model_;
  const Trajectory& reference_;
  double energyScale_ = 0.0, angularScale_ = 0.0, squares_ = 0.0;
  long samples_ = 0;
  Errors e_;
};

// One timed run over the window: set-up (the Simulation's construction), the first step (where
// the implicit integrators analyse and factor) and every step's time, taken apart from the
// error sampling.
struct Run {
  double setup = 0.0, firstStep = 0.0, steps = 0.0;  // s
  long count = 0;
  long forceEvaluations = 0;
  std::vector<Statistic> statistics;
  std::string failure;  // empty when every step succeeded
  Errors errors;
  Trajectory trajectory;  // when asked to keep it
};

// `kind` at dt over `time` s on `w`, sampled every `interval` (a whole number of steps): errors
// against `reference` when given, the samples kept when `keep`.
Run run(const World& w, IntegratorKind kind, double dt, double time, double interval,
        const SolverOptions& options, const Trajectory* reference, bool keep = false);

}  // namespace jello::experiments
