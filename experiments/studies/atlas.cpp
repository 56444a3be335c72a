#include "experiments/studies/atlas.h"

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

#include "experiments/studies/reference_file.h"
#include "experiments/studies/stability_analysis.h"
#include "experiments/studies/study_integrators.h"
#include "experiments/studies/trajectory_run.h"
#include "solvers/simulation.h"
#include "src/base/parallel.h"
#include "src/world/integrator_table.h"
#include "src/world/lattice.h"

namespace jello::experiments {

using Fit = Eigen::Matrix<double, 3, 4>;

VisibleMotion::VisibleMotion(int n) {
  const Lattice lattice{n};
  Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Vec3 p = lattice.restPosition(i, j, k);
        const Eigen::Vector3d r(p.x - 0.5, p.y - 0.5, p.z - 0.5);
        rest_.push_back(r);
        gram += r * r.transpose();
      }
    }
  }
  inverseGram_ = gram.inverse();
}

Fit VisibleMotion::fit(const State& s) const {
  // rest_ is in the lattice's point order (Lattice::index).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int p = 0; p < s.numPoints(); ++p) {
    const Vec3 x = s.position(p);
    mean += Eigen::Vector3d(x.x, x.y, x.z);
  }
  mean /= double(s.numPoints());
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (int p = 0; p < s.numPoints(); ++p) {
    const Vec3 x = s.position(p);
    cross += (Eigen::Vector3d(x.x, x.y, x.z) - mean) * rest_[std::size_t(p)].transpose();
  }
  Fit f;
  f.leftCols<3>() = cross * inverseGram_;
  f.col(3) = mean;
  return f;
}

double VisibleMotion::cornerDistance(const Fit& a, const Fit& b) const {
  const Fit d = a - b;
  double worst = 0.0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5);
    worst = std::max(worst, (d.leftCols<3>() * corner + d.col(3)).norm());
  }
  return worst;
}

namespace {

struct Attempt {
  bool finished = false;  // false: diverged, failed or over the budget
  std::string why;
  double error = 0.0;  // m
  double wallPerSecond = 0.0;
  long steps = 0;
};

// `kind` at dt (cvode: the sample interval) over the window, the visible motion compared with
// the reference's.
// `trace`, when given, is called with each sample's time and fit.
Attempt attempt(const World& w, IntegratorKind kind, double dt, const SolverOptions& options,
                const AtlasSetup& setup, const VisibleMotion& visible,
                const AtlasReference& reference,
                const std::function<void(double, const Fit&)>& trace = nullptr) {
  Simulation sim(w, kind, dt, options);
  const long perSample = std::max(1L, std::lround(setup.interval / dt));
  const long samples = std::lround(setup.time / setup.interval);
  Attempt a;
  double wall = 0.0;
  for (long k = 1; k <= samples; ++k) {
    const auto t0 = Clock::now();
    for (long i = 0; i < perSample; ++i) {
      const StepResult r = sim.step();
      if (!r.ok) {
        a.why = r.message;
        a.steps = sim.steps();
        return a;
      }
      // At the sample's end and within it every 16 steps: forward Euler's first sample alone at
      // N = 32 and k = 1e8 (its damped limit c/k) is millions of steps, hours.
      if ((i % 16 == 15 || i + 1 == perSample) && wall + secondsSince(t0) > setup.runBudget) {
        a.why = "over the run budget";
        a.steps = sim.steps();
        return a;
      }
    }
    wall += secondsSince(t0);
    const Fit fit = visible.fit(sim.state());
    a.error = std::max(a.error, visible.cornerDistance(fit, reference.samples[std::size_t(k)]));
    if (trace) trace(double(k) * setup.interval, fit);
  }
  a.finished = true;
  a.wallPerSecond = wall / setup.time;
  a.steps = sim.steps();
  return a;
}

// A run's end as a CSV cell (the messages hold commas): "", "budget", "diverged" or "failed".
std::string whyCell(const Attempt& a) {
  if (a.finished) return "";
  if (a.why == "over the run budget") return "budget";
  return a.why.rfind("diverged", 0) == 0 ? "diverged" : "failed";
}

// The model's threads set for a scope, and restored after.
class ThreadsFor {
 public:
  explicit ThreadsFor(int threads) : saved_(parallelThreads()) {
    if (threads > 0) setParallelThreads(threads);
  }
  ~ThreadsFor() { setParallelThreads(saved_); }
  ThreadsFor(const ThreadsFor&) = delete;
  ThreadsFor& operator=(const ThreadsFor&) = delete;

 private:
  int saved_;
};

// RK4 at key.dt over the window from w's initial state: the visible motion at every sample,
// read from, resumed from and written to the reference directory when there is one.
// Nothing when a step fails.
std::optional<std::vector<Fit>> referenceFits(const World& w, const TrajectoryKey& key,
                                              const AtlasSetup& setup,
                                              const VisibleMotion& visible) {
  const std::filesystem::path file =
      setup.referenceDir.empty() ? std::filesystem::path() : setup.referenceDir / key.fileName();
  std::vector<Fit> fits;
  Simulation sim(w, IntegratorKind::RK4, key.dt);
  if (!file.empty()) {
    if (std::optional<StoredTrajectory> stored = readTrajectory(file, key)) {
      fits = std::move(stored->fits);
      if (!stored->resume) return fits;
      std::fprintf(stderr, "jello-scaling: %s: resuming at t = %g s of %g\n", file.c_str(),
                   stored->resume->t, key.time);
      sim.editableState() = *stored->resume;
      sim.stateEdited();
    }
  }
  if (fits.empty()) fits.push_back(visible.fit(sim.state()));
  const long perSample = std::max(1L, std::lround(key.interval / key.dt));
  const long samples = std::lround(key.time / key.interval);
  auto saved = Clock::now();
  for (long k = long(fits.size()); k <= samples; ++k) {
    for (long i = 0; i < perSample; ++i) {
      const StepResult r = sim.step();
      if (!r.ok) {
        std::fprintf(stderr, "jello-scaling: the reference at dt = %g s failed: %s\n", key.dt,
                     r.message.c_str());
        return std::nullopt;
      }
    }
    fits.push_back(visible.fit(sim.state()));
    if (!file.empty() && k < samples && secondsSince(saved) >= setup.checkpoint) {
      writeTrajectory(file, key, fits, &sim.state());
      saved = Clock::now();
    }
  }
  if (!file.empty()) writeTrajectory(file, key, fits, nullptr);
  return fits;
}

}  // namespace

AtlasReference atlasReference(const World& w, double k, AtlasScene scene, const AtlasSetup& setup,
                              AtlasContact contact) {
  const ThreadsFor threads(setup.referenceThreads);
  AtlasReference ref;
  ref.wMax = atlasMaxFrequency(w, scene);
  ref.dt =
      setup.interval /
      std::pow(2.0,
               std::max(0.0, std::ceil(std::log2(setup.interval * ref.wMax / setup.referenceHw))));
  const VisibleMotion visible(w.cubeResolution);
  TrajectoryKey key{
      referenceSceneName(scene, contact), k, w.cubeResolution, ref.dt, setup.interval, setup.time};
  const auto fitsAt = [&](double dt) {
    key.dt = dt;
    return referenceFits(w, key, setup, visible);
  };
  std::optional<std::vector<Fit>> fine = fitsAt(ref.dt), coarse = fitsAt(2.0 * ref.dt);
  // Halved while RK4 at twice the step is further than setup.referenceCheck of the tolerance
  // from it (each halving's check the run before it: RK4's own error is then about a fifteenth
  // of the check), or while RK4 fails (a point crossing the barrier at the impact).
  for (int refinement = 0;; ++refinement) {
    ref.check = INFINITY;
    if (fine && coarse) {
      ref.check = 0.0;
      for (std::size_t i = 0; i < coarse->size(); ++i) {
        ref.check = std::max(ref.check, visible.cornerDistance((*coarse)[i], (*fine)[i]));
      }
    }
    if (fine && (ref.check <= setup.referenceCheck * setup.tolerance ||
                 refinement == setup.referenceRefinements)) {
      break;
    }
    if (refinement == setup.referenceRefinements) {
      throw AtlasReferenceFailed("atlas reference: RK4 failed at dt = " + std::to_string(ref.dt) +
                                 " s and at every halving of it");
    }
    coarse = std::move(fine);
    ref.dt /= 2.0;
    fine = fitsAt(ref.dt);
  }
  ref.samples = std::move(*fine);
  return ref;
}

std::vector<IntegratorKind> atlasIntegrators(bool quick) {
  return quick ? quickAtlasIntegrators() : studyOrder();
}

CsvTable atlasTable() {
  return CsvTable({"k_N_per_m", "n", "w_max_rad_per_s", "integrator", "dt_s", "rtol", "steps",
                   "wall_per_simulated_s", "visible_error_m", "tried", "outcome", "reference_dt_s",
                   "reference_check_m"});
}

namespace {

// The candidates of a search, largest first: explicit steps from 0.9 of the predicted limit
// (dividing the sample interval), the others from the interval (or setup.firstStep); cvode's
// tolerances from 1e-2.
// No steps: an explicit method never stable.
struct Candidates {
  std::vector<double> steps, rtols;
};
Candidates candidates(const World& w, IntegratorKind kind, double wMax, const AtlasSetup& setup) {
  Candidates c;
  if (isAdaptive(kind)) {
    for (int j = 0; j < setup.halvings; ++j) c.rtols.push_back(std::pow(10.0, -2 - j));
    return c;
  }
  double dt = setup.firstStep > 0.0 ? setup.firstStep : setup.interval;
  if (isExplicit(kind)) {
    const double limit = 0.9 * predictedThreshold(kind, wMax, w.dElastic / w.kElastic);
    if (limit <= 0.0) return c;
    dt = setup.interval / std::ceil(setup.interval / limit);
  }
  for (int j = 0; j < setup.halvings; ++j, dt /= 2.0) c.steps.push_back(dt);
  return c;
}

// The row of an integrator not run at a point: `outcome` says why.
void addUnrun(CsvTable& table, double k, int n, double wMax, IntegratorKind kind,
              const std::string& outcome, double referenceDt, double referenceCheck) {
  const double nan = std::nan("");
  table.add({k, long(n), wMax, std::string(integratorName(kind)), nan, nan, 0L, nan, nan, 0L,
             outcome, referenceDt, referenceCheck});
}

SolverOptions cvodeAt(double rtol) {
  SolverOptions options;
  options.cvode.rtol = rtol;
  options.cvode.maxStepsPerCall = 100000000;
  return options;
}

}  // namespace

CsvTable atlasTriesTable() {
  return CsvTable({"k_N_per_m", "n", "integrator", "dt_s", "rtol", "steps", "wall_per_simulated_s",
                   "visible_error_m", "finished", "why"});
}

void atlasPoint(const World& w, double k, int n, IntegratorKind kind, const AtlasReference& ref,
                const AtlasSetup& setup, CsvTable& table, CsvTable* tries) {
  const double wMax = ref.wMax;
  const VisibleMotion visible(n);
  const double nan = std::nan("");
  const Candidates c = candidates(w, kind, wMax, setup);
  const std::vector<double>&steps = c.steps, &rtols = c.rtols;
  if (steps.empty() && rtols.empty()) {
    addUnrun(table, k, n, wMax, kind, "never_stable", ref.dt, ref.check);
    return;
  }
  const std::size_t count = isAdaptive(kind) ? rtols.size() : steps.size();
  long tried = 0;
  double lastWall = 0.0, lastError = nan;
  std::string outcome = "not_reached";
  for (std::size_t i = 0; i < count; ++i) {
    // Halving the step doubles the cost: a run that would exceed the budget is not started.
    if (!isAdaptive(kind) && 2.0 * lastWall * setup.time > setup.runBudget) {
      outcome = "budget";
      break;
    }
    const SolverOptions options = isAdaptive(kind) ? cvodeAt(rtols[i]) : SolverOptions{};
    const double dt = isAdaptive(kind) ? setup.interval : steps[i];
    const Attempt a = attempt(w, kind, dt, options, setup, visible, ref);
    ++tried;
    if (tries) {
      tries->add({k, long(n), std::string(integratorName(kind)), dt,
                  isAdaptive(kind) ? rtols[i] : nan, a.steps, a.finished ? a.wallPerSecond : nan,
                  a.error, long(a.finished), whyCell(a)});
    }
    if (!a.finished && a.why == "over the run budget") {
      outcome = "budget";
      break;
    }
    lastWall = a.wallPerSecond;
    lastError = a.finished ? a.error : nan;
    if (a.finished && a.error <= setup.tolerance) {
      table.add({k, long(n), wMax, std::string(integratorName(kind)), dt,
                 isAdaptive(kind) ? rtols[i] : nan, a.steps, a.wallPerSecond, a.error, tried,
                 std::string("ok"), ref.dt, ref.check});
      return;
    }
  }
  table.add({k, long(n), wMax, std::string(integratorName(kind)), nan, nan, 0L, nan, lastError,
             tried, outcome, ref.dt, ref.check});
}

void atlasNoReference(double k, int n, double wMax, IntegratorKind kind, CsvTable& table) {
  addUnrun(table, k, n, wMax, kind, "no_reference", std::nan(""), std::nan(""));
}

CsvTable atlasTraceTable() {
  return CsvTable({"k_N_per_m", "n", "integrator", "dt_s", "rtol", "t_s", "centre_z_m", "height_m",
                   "width_m", "corner_distance_m"});
}

void atlasTrace(const World& w, double k, int n, std::optional<IntegratorKind> kind,
                const AtlasReference& ref, const AtlasSetup& setup, CsvTable& table) {
  const VisibleMotion visible(n);
  const double nan = std::nan("");
  const auto add = [&](const std::string& name, double dt, double rtol, double t, const Fit& fit) {
    const Fit& at = ref.samples[std::size_t(std::lround(t / setup.interval))];
    table.add({k, long(n), name, dt, rtol, t, fit(2, 3), fit(2, 2), fit(0, 0),
               visible.cornerDistance(fit, at)});
  };
  if (!kind) {
    for (std::size_t i = 0; i < ref.samples.size(); ++i) {
      add("reference", ref.dt, nan, double(i) * setup.interval, ref.samples[i]);
    }
    return;
  }
  const Candidates c = candidates(w, *kind, ref.wMax, setup);
  if (c.steps.empty() && c.rtols.empty()) return;
  const bool adaptive = isAdaptive(*kind);
  const double dt = adaptive ? setup.interval : c.steps.front();
  const double rtol = adaptive ? c.rtols.front() : nan;
  const std::string name(integratorName(*kind));
  attempt(w, *kind, dt, adaptive ? cvodeAt(rtol) : SolverOptions{}, setup, visible, ref,
          [&](double t, const Fit& fit) { add(name, dt, rtol, t, fit); });
}

}  // namespace jello::experiments
