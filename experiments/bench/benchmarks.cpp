// Speed of the core (Google Benchmark; run on one core, e.g.
// `taskset -c 0 build/native/bin/benchmarks`). Figures are reported in the README with the
// machine.
//   BM_SpringForces/N    one evaluation of every spring; items/s = spring evaluations/s
//   BM_Step/<integrator>/N  one full step on jello.w resampled to N^3; items/s = steps/s
//   BM_Threads/...       the spring forces, an RK4 step and the matrix-free product on 1 and 2
//                        threads (no taskset)
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "solvers/linalg/solver_threads.h"
#include "solvers/simulation.h"
#include "solvers/system/jacobian.h"
#include "solvers/system/system_operator.h"
#include "src/base/parallel.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"

namespace {

const jello::World& jelloWorld() {
  static const jello::World world =
      jello::readWorld(std::filesystem::path(JELLO_WORLDS_DIR) / "jello.w");
  return world;
}

void BM_SpringForces(benchmark::State& state) {
  const jello::World world = jello::resampleCube(jelloWorld(), static_cast<int>(state.range(0)));
  const jello::Model model(world);
  const jello::State s = jello::initialState(world);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(s.x.size());
  for (auto _ : state) {
    model.springs().accumulate(s.x.data(), s.v.data(), f.data());
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * model.springs().numSprings());
  state.counters["springs"] = model.springs().numSprings();
}
BENCHMARK(BM_SpringForces)->Arg(8)->Arg(16)->Arg(32);

void BM_Step(benchmark::State& state, jello::IntegratorKind kind) {
  const jello::World world = jello::resampleCube(jelloWorld(), static_cast<int>(state.range(0)));
  auto sim = std::make_unique<jello::Simulation>(world, kind);
  long restarts = 0;
  for (auto _ : state) {
    if (!sim->step().ok) {
      // Explicit Euler diverges on jello.w after ~12 s at rest on the plane: start the scene
      // again, outside the timing, and count it.
      state.PauseTiming();
      sim = std::make_unique<jello::Simulation>(world, kind);
      ++restarts;
      state.ResumeTiming();
    }
  }
  state.counters["restarts"] = static_cast<double>(restarts);
  state.SetItemsProcessed(state.iterations());
}

// Every explicit integrator of the table at N = 8, RK4 (the reference explicit method) also at
// 16 and 32: registered by main() before the benchmarks are listed.
void registerStepBenchmarks() {
  for (jello::IntegratorKind kind : jello::integratorsOf({jello::IntegratorFamily::Explicit})) {
    auto* b = benchmark::RegisterBenchmark(
        ("BM_Step/" + std::string(jello::integratorName(kind))).c_str(),
        [kind](benchmark::State& st) { BM_Step(st, kind); });
    b->Arg(8);
    if (kind == jello::IntegratorKind::RK4) b->Arg(16)->Arg(32);
  }
}

// Both cores (src/base/parallel.h): the spring forces, a whole RK4 step and the implicit solvers'
// matrix-free product (backward Euler's matrix at dt = 0.01) at N^3 with the given number of
// threads, 1 (serial) against 2, in one run. Run without taskset.
enum class ThreadedWork { Springs, Rk4Step, Product };

void BM_Threads(benchmark::State& state, ThreadedWork what) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  jello::setParallelThreads(threads);
  const jello::World world = jello::resampleCube(jelloWorld(), n);
  jello::Simulation sim(world, jello::IntegratorKind::RK4);
  const jello::State s = jello::initialState(world);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(s.x.size());
  jello::JacobianAssembler jacobian(sim.model());
  jacobian.assemble(s.x.data(), {});
  jello::SparseMatrix A = jacobian.pattern();
  jacobian.combine(0.01, 1e-4, A);
  jello::SystemOperator product(sim.model().springs(), sim.model().numPoints());
  product.gather(A, jacobian.diagonalSlots(), jacobian.springSlots());
  for (auto _ : state) {
    switch (what) {
      case ThreadedWork::Springs:
        sim.model().springs().accumulate(s.x.data(), s.v.data(), f.data());
        break;
      case ThreadedWork::Rk4Step:
        if (!sim.step().ok) state.SkipWithError("diverged");
        break;
      case ThreadedWork::Product:
        product.apply(s.v.data(), f.data());
        break;
    }
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  state.counters["threads"] = threads;
  jello::setParallelThreads(1);
}
BENCHMARK_CAPTURE(BM_Threads, springs, ThreadedWork::Springs)
    ->ArgNames({"N", "threads"})
    ->ArgsProduct({{16, 32}, {1, 2}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Threads, rk4_step, ThreadedWork::Rk4Step)
    ->ArgNames({"N", "threads"})
    ->ArgsProduct({{16, 32}, {1, 2}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Threads, product, ThreadedWork::Product)
    ->ArgNames({"N", "threads"})
    ->ArgsProduct({{16, 32}, {1, 2}})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace

// benchmarks_implicit.cpp
void registerImplicitStepBenchmarks();

int main(int argc, char** argv) {
  // Single-threaded BLAS and CHOLMOD (see solvers/linalg/solver_threads.h).
  jello::applySolverThreadSettings();
  benchmark::AddCustomContext("blas", jello::loadedBlas());
  benchmark::AddCustomContext("solver_threads", jello::solverThreadSettings());
  for (const char* name : {"OPENBLAS_NUM_THREADS", "OMP_THREAD_LIMIT", "OMP_WAIT_POLICY"}) {
    const char* value = std::getenv(name);
    benchmark::AddCustomContext(name, value ? value : "");
  }
  registerStepBenchmarks();
  registerImplicitStepBenchmarks();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
