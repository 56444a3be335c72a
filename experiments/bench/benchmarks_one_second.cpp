// One simulated second of a scene (Google Benchmark), split from benchmarks_implicit.cpp:
//   BM_CvodeOneSecond/<rtol>_<solver or adams>  jello.w for 1 simulated second (counters: CVODE
//                               statistics)
//   BM_StiffOneSecond/<method>/E  stiffCube(10^E) for 1 simulated second: implicit at
//                               dt = 0.01 against RK4 at its largest stable dt (bisection)
//   BM_Crossover/<method>/E     1 simulated second of the spinning stretched cube at k = 10^E
//                               with damping 0.25 (8^3): projective at dt = 1/60, implicit and
//                               bdf2 at dt = 0.01 (also in fastNewton's configuration), RK4 at
//                               0.9 of its measured stability limit;
//                               the time is wall time per simulated second after a first step
//                               timed apart with the set-up (counter setup_s); medians of 3
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>

#include "experiments/bench/bench_scenes.h"
#include "solvers/simulation.h"
#include "src/world/scene_builder.h"

namespace {

using namespace jello;
using bench::fastNewton;
using bench::jelloAt;

// Runs `sim` to t = 1 s; false if it diverged.
bool runOneSecond(Simulation& sim) {
  const long steps = std::lround(1.0 / sim.dt());
  for (long i = 0; i < steps; ++i) {
    if (!sim.step().ok) return false;
  }
  return true;
}

void BM_CvodeOneSecond(benchmark::State& st, double rtol, LinearSolverKind kind,
                       CvodeMethod method = CvodeMethod::Bdf, bool krylov = false,
                       bool fastVectors = true) {
  SolverOptions options;
  options.cvode.rtol = rtol;
  options.cvode.linearSolver = kind;
  options.cvode.method = method;
  options.cvode.krylov = krylov;
  options.cvode.fastVectors = fastVectors;
  for (auto _ : st) {
    Simulation sim(jelloAt(8), IntegratorKind::Cvode, 0.01, options);
    if (!runOneSecond(sim)) st.SkipWithError("cvode failed");
    for (const Statistic& s : sim.integrator().statistics()) st.counters[s.name] = s.value;
  }
}
// One run each, three repetitions: the table reports the medians.
#define JELLO_CVODE_SECOND(name, ...)                     \
  BENCHMARK_CAPTURE(BM_CvodeOneSecond, name, __VA_ARGS__) \
      ->Iterations(1)                                     \
      ->Repetitions(3)                                    \
      ->ReportAggregatesOnly(true)                        \
      ->Unit(benchmark::kSecond)
JELLO_CVODE_SECOND(rtol1e3_cholmod, 1e-3, LinearSolverKind::Cholmod);
JELLO_CVODE_SECOND(rtol1e3_cg, 1e-3, LinearSolverKind::Cg);
JELLO_CVODE_SECOND(rtol1e3_cg_sundials_vectors, 1e-3, LinearSolverKind::Cg, CvodeMethod::Bdf, false,
                   false);
JELLO_CVODE_SECOND(rtol1e3_adams, 1e-3, LinearSolverKind::Cg, CvodeMethod::Adams);
JELLO_CVODE_SECOND(rtol1e3_adams_sundials_vectors, 1e-3, LinearSolverKind::Cg, CvodeMethod::Adams,
                   false, false);
JELLO_CVODE_SECOND(rtol1e3_spgmr, 1e-3, LinearSolverKind::Cholmod, CvodeMethod::Bdf, true);
BENCHMARK_CAPTURE(BM_CvodeOneSecond, rtol1e6_cholmod, 1e-6, LinearSolverKind::Cholmod)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_CvodeOneSecond, rtol1e6_cg, 1e-6, LinearSolverKind::Cg)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// The largest dt at which RK4 runs the stiff cube for 0.1 s without diverging (bisection to
// 1%), then 5% below it for safety over the full second.
double largestStableRk4Step(const World& w, double margin = 0.95) {
  double stable = 1e-6, unstable = 1e-2;
  while (unstable / stable > 1.01) {
    const double dt = std::sqrt(stable * unstable);
    Simulation sim(w, IntegratorKind::RK4, dt);
    bool ok = true;
    for (long i = 0; ok && i < std::lround(0.1 / dt); ++i) ok = sim.step().ok;
    (ok ? stable : unstable) = dt;
  }
  return margin * stable;
}

void BM_StiffOneSecond(benchmark::State& st, IntegratorKind kind, LinearSolverKind solver) {
  const World w = buildWorld(stiffCube(std::pow(10.0, static_cast<double>(st.range(0)))));
  const double dt = kind == IntegratorKind::RK4 ? largestStableRk4Step(w) : 0.01;
  SolverOptions options;
  options.implicit.linearSolver = solver;
  for (auto _ : st) {
    Simulation sim(w, kind, dt, options);
    if (!runOneSecond(sim)) st.SkipWithError("diverged");
  }
  st.counters["dt_s"] = dt;
}
BENCHMARK_CAPTURE(BM_StiffOneSecond, rk4_at_its_limit, IntegratorKind::RK4,
                  LinearSolverKind::Cholmod)
    ->Arg(5)
    ->Arg(6)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_StiffOneSecond, implicit_cholmod_dt001, IntegratorKind::Implicit,
                  LinearSolverKind::Cholmod)
    ->Arg(5)
    ->Arg(6)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_StiffOneSecond, implicit_cg_dt001, IntegratorKind::Implicit,
                  LinearSolverKind::Cg)
    ->Arg(5)
    ->Arg(6)
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

void BM_Crossover(benchmark::State& st, IntegratorKind kind, const SolverOptions& options = {}) {
  const World w = buildWorld(vibratingStiffCube(std::pow(10.0, static_cast<double>(st.range(0)))));
  double dt = 0.01;
  if (kind == IntegratorKind::Projective) dt = 1.0 / 60.0;
  if (kind == IntegratorKind::RK4) dt = largestStableRk4Step(w, 0.9);
  for (auto _ : st) {
    // Set-up timed apart: the model, the integrator and its first step (a kept factor's
    // analysis and factorization, a Newton solver's pattern), then one simulated second.
    st.PauseTiming();
    const auto start = std::chrono::steady_clock::now();
    Simulation sim(w, kind, dt, options);
    if (!sim.step().ok) st.SkipWithError("diverged");
    st.counters["setup_s"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    st.ResumeTiming();
    if (!runOneSecond(sim)) st.SkipWithError("diverged");
  }
  st.counters["dt_s"] = dt;
}
// One simulated second per repetition, three repetitions: the table reports the medians.
#define JELLO_CROSSOVER_BENCHMARK(name, ...)         \
  BENCHMARK_CAPTURE(BM_Crossover, name, __VA_ARGS__) \
      ->Arg(4)                                       \
      ->Arg(5)                                       \
      ->Iterations(1)                                \
      ->Repetitions(3)                               \
      ->ReportAggregatesOnly(true)                   \
      ->Unit(benchmark::kMillisecond)
JELLO_CROSSOVER_BENCHMARK(rk4, IntegratorKind::RK4);
JELLO_CROSSOVER_BENCHMARK(projective, IntegratorKind::Projective);
JELLO_CROSSOVER_BENCHMARK(implicit, IntegratorKind::Implicit);
JELLO_CROSSOVER_BENCHMARK(bdf2, IntegratorKind::Bdf2);
JELLO_CROSSOVER_BENCHMARK(implicit_cholmod, IntegratorKind::Implicit, [] {
  SolverOptions o;
  o.implicit.linearSolver = LinearSolverKind::Cholmod;
  return o;
}());
JELLO_CROSSOVER_BENCHMARK(implicit_fast, IntegratorKind::Implicit, fastNewton());
JELLO_CROSSOVER_BENCHMARK(bdf2_fast, IntegratorKind::Bdf2, fastNewton());

}  // namespace
