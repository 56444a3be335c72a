// Speed of the implicit machinery (Google Benchmark). Figures are reported in the README.
//   BM_Refill/N          assemble K and D in place at a deformed state
//   BM_OperatorFill/N/filled  A's operator for CG: gathered from the assembled sparse A (0), or
//                        filled straight from the springs (1)
//   BM_Factorize/N       CHOLMOD supernodal LLT of M - h D - h^2 K, h = 0.01
//   BM_Solve/N           CHOLMOD triangular solves
//   BM_CgSolve/N         Jacobi-CG at tolerance 1e-6, warm-started from the last step
//   BM_ImplicitStep/<solver>/N  one backward-Euler step at dt = 0.01 on jello.w at N^3
//   BM_ImplicitIntegratorStep/<integrator>/N/spinning  one step at dt = 0.01 after a first
//                               step timed apart (counter first_step_ms: set-up); projective: 10
//                               iterations, also at N = 32; the defaults solve by CG
//                               with Jacobi; implicit_cholmod: by CHOLMOD; implicit_fast:
//                               fastNewton() below)
//   BM_ProjectiveStep/<global>/N/spinning/threads  projective's step (10 iterations, dt = 0.01)
//                               as BM_ImplicitIntegratorStep's, on 1 or 2 threads (the pool of
//                               src/base/parallel.h; run without taskset), its global step by
//                               the default (spectral: the cosine transform's bound from 16^3
//                               up) or by the CHOLMOD factor at every N (factor: spectralFrom 0,
//                               the same-run baseline); 300, 100 and 30 steps at N = 8, 16
//                               and 32 (scripts/projective-speed.py)
//   BM_KeptFactorSolve/<copy|single|cholmod>/N  three right-hand sides solved with projective's
//                               kept factor M/h^2 + L at N^3 (h = 0.01): our own substitutions
//                               over the copied factor or over its supernodes in single
//                               precision, or CHOLMOD's cholmod_solve2 (counter nnz_L)
//   BM_ContactRun/<integrator>/<model>/N  jello.w at N^3 under a contact model for 30 steps at
//                               dt = 0.01 (its cube meets the walls and the plane): projective,
//                               implicit and implicit_fast (fastNewton() below), wall time
//                               per step over steps 2-30 (manual time; the first, with the
//                               set-up, left out); counters: Newton iterations per step,
//                               unconverged steps, factorizations, factor updates, contact-set
//                               changes, barrier cuts, coarse corrections
//                               (scripts/contact-speed.py)
//   (one simulated second of a scene, CVODE's and the crossover: benchmarks_one_second.cpp)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "experiments/bench/bench_scenes.h"
#include "solvers/linalg/linear_solver.h"
#include "solvers/linalg/prefactored_cholesky.h"
#include "solvers/methods/newton_integrators.h"
#include "solvers/simulation.h"
#include "solvers/system/jacobian.h"
#include "solvers/system/spring_laplacian.h"
#include "solvers/system/system_operator.h"
#include "src/base/parallel.h"
#include "src/world/scene_builder.h"
#include "src/world/world_reader.h"

namespace jello::bench {

World jelloAt(int n) {
  return resampleCube(readWorld(std::filesystem::path(JELLO_WORLDS_DIR) / "jello.w"), n);
}

// The converged Newton methods' fastest configuration measured (ImplicitOptions::fast()):
// 10 Chebyshev seeds, then plain Newton on the exact Jacobian, clamped on demand, with A filled
// straight from the springs at every iteration and each update solved by CG to 1e-2,
// preconditioned by the projective matrix. Measured with jello-sim on jello.w, 100 steps,
// smooth contact (one core): 2.1 ms a step; 0 seeds 2.5 ms; 20 seeds and CG to 1e-3 2.5 ms; the
// earlier configuration (60 seeds to 1e-8, CG to 1e-6) 4.4 ms; spinning cube 1.0-1.3 ms for all
// but the 60 seeds (2.1 ms).
SolverOptions fastNewton() {
  SolverOptions o;
  o.implicit = ImplicitOptions::fast();
  return o;
}

}  // namespace jello::bench

namespace {

using namespace jello;
using bench::fastNewton;
using bench::jelloAt;

// jello.w after 0.05 s of RK4: deformed, moving, in contact with nothing in particular.
State movingState(const World& w) {
  Simulation sim(w);
  for (int i = 0; i < 100; ++i) (void)sim.step();
  return sim.state();
}

void BM_Refill(benchmark::State& st) {
  const World w = jelloAt(static_cast<int>(st.range(0)));
  const Model model(w);
  const State s = movingState(w);
  JacobianAssembler jac(model);
  for (auto _ : st) {
    jac.assemble(s.x.data(), {});
    benchmark::DoNotOptimize(jac.K().valuePtr());
  }
  st.counters["nonzeros"] = static_cast<double>(jac.K().nonZeros());
}
BENCHMARK(BM_Refill)->Arg(8)->Arg(16)->Unit(benchmark::kMicrosecond);

// What a Newton iteration pays for A = M - a D - b K (a = 0.01, b = 1e-4) before CG multiplies:
// gathered, K and D refilled, combined into A and gathered into the operator (as before; mode 0),
// or filled, the other effects' diagonal blocks assembled and the springs' blocks filled straight
// from the positions (SystemOperator::fill; mode 1).
void BM_OperatorFill(benchmark::State& st) {
  const World w = jelloAt(static_cast<int>(st.range(0)));
  const Model model(w);
  const State s = movingState(w);
  JacobianAssembler jac(model);
  SystemOperator op(model.springs(), model.numPoints());
  SparseMatrix A = jac.pattern();
  const bool filled = st.range(1) == 1;
  for (auto _ : st) {
    if (filled) {
      JacobianOptions options;
      options.includeSprings = false;
      jac.assemble(s.x.data(), options);
      benchmark::DoNotOptimize(op.fill(s.x.data(), model.mass(), 0.01, 1e-4, true,
                                       jac.diagonalK().data(), jac.diagonalD().data()));
    } else {
      jac.assemble(s.x.data(), {});
      jac.combine(0.01, 1e-4, A);
      op.gather(A, jac.diagonalSlots(), jac.springSlots());
    }
    benchmark::DoNotOptimize(op.diagonalBlocks()[0]);
  }
}
BENCHMARK(BM_OperatorFill)
    ->ArgsProduct({{8, 16}, {0, 1}})
    ->ArgNames({"N", "filled"})
    ->Unit(benchmark::kMicrosecond);

struct System {
  World w;
  Model model;
  State s;
  JacobianAssembler jac;
  SparseMatrix A;
  Eigen::VectorXd b;
  explicit System(int n) : w(jelloAt(n)), model(w), s(movingState(w)), jac(model) {
    jac.assemble(s.x.data(), {});
    A = jac.pattern();
    jac.combine(0.01, 1e-4, A);
    model.forces(s.x, s.v, b);
    b *= 0.01;
  }
};

void BM_Factorize(benchmark::State& st) {
  System sys(static_cast<int>(st.range(0)));
  SpdSolver solver(LinearSolverKind::Cholmod);
  for (auto _ : st) {
    if (!solver.factorize(sys.A).ok) st.SkipWithError("factorization failed");
  }
}
BENCHMARK(BM_Factorize)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);

void BM_Solve(benchmark::State& st) {
  System sys(static_cast<int>(st.range(0)));
  SpdSolver solver(LinearSolverKind::Cholmod);
  if (!solver.factorize(sys.A).ok) st.SkipWithError("factorization failed");
  Eigen::VectorXd x;
  for (auto _ : st) {
    if (!solver.solve(sys.b, x).ok) st.SkipWithError("solve failed");
  }
}
BENCHMARK(BM_Solve)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);

// One CG solve of jello.w's system (dt = 0.01), warm-started as in a time step: last step's
// answer, the right-hand side moved by 1%. Arguments: N, the preconditioner (0 jacobi, 1
// block-jacobi, 2 ichol, 3 factor, 4 projective) and the product (1 matrix-free, 0 the sparse
// matrix). The set-up (a preconditioner's factorization, the operator's gathering) is outside the
// timing.
void BM_CgSolve(benchmark::State& st) {
  System sys(static_cast<int>(st.range(0)));
  const auto pre = static_cast<PreconditionerKind>(st.range(1));
  const bool matrixFree = st.range(2) != 0;
  SpdSolver solver(LinearSolverOptions{LinearSolverKind::Cg, 1e-6, pre, matrixFree});
  SystemOperator op(sys.model.springs(), sys.model.numPoints());
  op.gather(sys.A, sys.jac.diagonalSlots(), sys.jac.springSlots());
  // projective: M + L(a c + b k) with the same a = 0.01, b = 1e-4 (jello.w's moving state
  // touches nothing, so no contact term).
  const SpringLaplacian laplacian(sys.model);
  SparseMatrix P;
  laplacian.form(sys.model.mass(), 0.01, 1e-4, nullptr, P);
  PrefactoredCholesky projective;
  if (!projective.factorize(P).ok) st.SkipWithError("projective factorization failed");
  if (!solver.factorize(sys.A, matrixFree ? &op : nullptr, &projective).ok) {
    st.SkipWithError("set-up failed");
  }
  Eigen::VectorXd x0;
  if (!solver.solve(sys.b, x0).ok) st.SkipWithError("solve failed");
  const Eigen::VectorXd b = sys.b * 1.01;
  const long before = solver.stats().cgIterations;
  for (auto _ : st) {
    Eigen::VectorXd x = x0;
    if (!solver.solve(b, x).ok) st.SkipWithError("solve failed");
  }
  st.counters["iterations"] =
      benchmark::Counter(static_cast<double>(solver.stats().cgIterations - before),
                         benchmark::Counter::kAvgIterations);
  st.SetLabel(std::string(preconditionerName(pre)) + (matrixFree ? ", matrix-free" : ", csr"));
}
BENCHMARK(BM_CgSolve)
    ->ArgNames({"N", "pre", "mf"})
    ->ArgsProduct({{8, 16}, {0, 1, 2, 3, 4}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// The product alone: the sparse matrix against the spring kernels.
void BM_SystemProduct(benchmark::State& st) {
  System sys(static_cast<int>(st.range(0)));
  SystemOperator op(sys.model.springs(), sys.model.numPoints());
  op.gather(sys.A, sys.jac.diagonalSlots(), sys.jac.springSlots());
  const Eigen::VectorXd p = sys.b;
  Eigen::VectorXd y(p.size());
  const bool matrixFree = st.range(1) != 0;
  for (auto _ : st) {
    if (matrixFree) {
      op.apply(p.data(), y.data());
    } else {
      y.noalias() = sys.A * p;
    }
    benchmark::DoNotOptimize(y.data());
  }
  st.SetLabel(matrixFree ? "matrix-free" : "csr");
}
BENCHMARK(BM_SystemProduct)
    ->ArgNames({"N", "mf"})
    ->ArgsProduct({{8, 16, 32}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

void BM_ImplicitStep(benchmark::State& st, LinearSolverKind kind) {
  SolverOptions options;
  options.implicit.linearSolver = kind;
  Simulation sim(jelloAt(static_cast<int>(st.range(0))), IntegratorKind::Implicit, 0.01, options);
  for (auto _ : st) {
    if (!sim.step().ok) st.SkipWithError("step failed");
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK_CAPTURE(BM_ImplicitStep, cholmod, LinearSolverKind::Cholmod)
    ->Arg(8)
    ->Arg(16)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ImplicitStep, cg, LinearSolverKind::Cg)
    ->Arg(8)
    ->Arg(16)
    ->Unit(benchmark::kMillisecond);

// One step of every implicit integrator at dt = 0.01, on jello.w and on the spinning,
// stretched, undamped stiff cube (k = 1e4), resampled to N^3 (range 0: N; 1: 0 jello, 1 cube):
// the converged ones take several factorizations a step (counter newton_per_step).

void BM_ImplicitIntegratorStep(benchmark::State& st, IntegratorKind kind,
                               const SolverOptions& options = {}) {
  const int n = static_cast<int>(st.range(0));
  SceneSpec spinning = vibratingStiffCube(1e4);
  spinning.dElastic = 0.0;
  const World w = st.range(1) == 0 ? jelloAt(n) : resampleCube(buildWorld(spinning), n);
  Simulation sim(w, kind, 0.01, options);
  // The first step (a factor's analysis, the first factorization) is set-up: timed apart.
  const auto start = std::chrono::steady_clock::now();
  if (!sim.step().ok) st.SkipWithError("first step failed");
  st.counters["first_step_ms"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (auto _ : st) {
    if (!sim.step().ok) st.SkipWithError("step failed");
  }
  for (const Statistic& s : sim.integrator().statistics()) {
    if (s.name == "newton_iterations_per_step") st.counters["newton_per_step"] = s.value;
    if (s.name == "newton_unconverged_steps") st.counters["unconverged"] = s.value;
  }
}
void BM_ProjectiveStep(benchmark::State& st, bool factor) {
  setParallelThreads(static_cast<int>(st.range(2)));
  SolverOptions options;
  if (factor) options.projective.spectralFrom = 0;
  BM_ImplicitIntegratorStep(st, IntegratorKind::Projective, options);
  st.counters["threads"] = static_cast<double>(st.range(2));
  setParallelThreads(1);
}
// A fixed number of steps per size (jello.w's contacts develop over its steps: every repetition
// and both global steps time the same steps).
const bool kProjectiveStepRegistered = [] {
  for (const auto& [n, steps] : {std::pair{8, 300}, std::pair{16, 100}, std::pair{32, 30}}) {
    for (bool factor : {false, true}) {
      benchmark::RegisterBenchmark(
          factor ? "BM_ProjectiveStep/factor" : "BM_ProjectiveStep/spectral",
          [factor](benchmark::State& st) { BM_ProjectiveStep(st, factor); })
          ->ArgsProduct({{n}, {0, 1}, {1, 2}})
          ->ArgNames({"N", "spinning", "threads"})
          ->Iterations(steps)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  }
  return true;
}();
// BM_ContactRun (above): a fresh run per iteration, so every iteration meets the same contacts.
void BM_ContactRun(benchmark::State& st, IntegratorKind kind, ContactModel model,
                   const SolverOptions& options) {
  constexpr int kSteps = 30;
  World w = jelloAt(static_cast<int>(st.range(0)));
  w.contact.model = model;
  if (model == ContactModel::Smooth) w.contact.layer = kDefaultContactLayer;
  if (model == ContactModel::Barrier) {
    w.contact.dhat = kDefaultBarrierDistance;
    w.contact.kappa = w.kCollision;
  }
  std::vector<Statistic> stats;
  for (auto _ : st) {
    Simulation sim(w, kind, 0.01, options);
    if (!sim.step().ok) st.SkipWithError("first step failed");
    const auto start = std::chrono::steady_clock::now();
    for (int i = 1; i < kSteps; ++i) {
      if (!sim.step().ok) st.SkipWithError("step failed");
    }
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    st.SetIterationTime(took.count() / (kSteps - 1));
    stats = sim.integrator().statistics();
  }
  for (const Statistic& s : stats) {
    for (const char* name :
         {"newton_iterations_per_step", "newton_unconverged_steps", "factorizations",
          "factor_updates", "contact_set_changes", "barrier_cuts", "coarse_corrections",
          "factor_time_s", "solve_time_s"}) {
      if (s.name == name) st.counters[name] = s.value;
    }
  }
}

}  // namespace

// Every implicit integrator of the table (src/world/integrator_table.h) at N = 8 and 16 on both
// scenes, backward Euler also in two other configurations, projective also at N = 32: called
// from main() before the benchmarks are listed, so a new row is measured without a change here.
void registerImplicitStepBenchmarks() {
  const auto add = [](const std::string& name, IntegratorKind kind, const SolverOptions& options,
                      std::vector<std::int64_t> ns) {
    benchmark::RegisterBenchmark(
        ("BM_ImplicitIntegratorStep/" + name).c_str(),
        [kind, options](benchmark::State& st) { BM_ImplicitIntegratorStep(st, kind, options); })
        ->ArgsProduct({ns, {0, 1}})
        ->ArgNames({"N", "spinning"})
        ->Unit(benchmark::kMillisecond);
  };
  using F = IntegratorFamily;
  for (IntegratorKind kind : integratorsOf({F::Newton, F::Linearized, F::Projective})) {
    std::string name(integratorName(kind));
    std::replace(name.begin(), name.end(), '-', '_');
    add(name, kind, {}, {8, 16});
    if (kind == IntegratorKind::Implicit) {
      SolverOptions cholmod;
      cholmod.implicit.linearSolver = LinearSolverKind::Cholmod;
      add(name + "_cholmod", kind, cholmod, {8, 16});
      add(name + "_fast", kind, fastNewton(), {8, 16});
    }
  }
  add("projective", IntegratorKind::Projective, {}, {32});
  const std::string implicitName(integratorName(IntegratorKind::Implicit));
  for (const auto& [name, kind, options] :
       {std::tuple{std::string(integratorName(IntegratorKind::Projective)),
                   IntegratorKind::Projective, SolverOptions{}},
        std::tuple{implicitName, IntegratorKind::Implicit, SolverOptions{}},
        std::tuple{implicitName + "_fast", IntegratorKind::Implicit, fastNewton()}}) {
    // The seeded Newton at 8^3 alone: at 16^3 jello.w's impacts cost it about 50 Newton
    // iterations a step, minutes a run. Plain Newton at 16^3 (seconds a step) is run once.
    const bool fast = name != implicitName && kind == IntegratorKind::Implicit;
    for (ContactModel model : allContactModels()) {
      for (int n : {8, 16}) {
        if (fast && n == 16) continue;
        benchmark::RegisterBenchmark(
            ("BM_ContactRun/" + name + "/" + std::string(contactModelName(model))).c_str(),
            [kind, model, options](benchmark::State& st) {
              BM_ContactRun(st, kind, model, options);
            })
            ->Arg(n)
            ->ArgName("N")
            ->UseManualTime()
            ->Iterations(kind == IntegratorKind::Implicit && n == 16 ? 1 : 3)
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
}

namespace {

enum class KeptFactorWay { Copy, Single, Cholmod };

void BM_KeptFactorSolve(benchmark::State& st, KeptFactorWay way) {
  const Model model(jelloAt(static_cast<int>(st.range(0))));
  const SpringLaplacian laplacian(model);
  SparseMatrix A;
  laplacian.form(model.mass() / 1e-4, 0.0, 1.0, nullptr, A);
  PrefactoredCholesky factor(
      way == KeptFactorWay::Copy ? PrefactoredCholesky::kDefaultCopyLimit * 1000 : 0,
      way == KeptFactorWay::Single);
  if (!factor.factorize(A).ok) st.SkipWithError("factorization failed");
  const Eigen::VectorXd start = Eigen::VectorXd::LinSpaced(3 * model.numPoints(), -1.0, 1.0);
  Eigen::VectorXd b = start;
  for (auto _ : st) {
    // The same right-hand side each time: solved in place again and again it would shrink
    // into subnormal numbers (A's smallest eigenvalue is M/h^2 > 1), which time differently.
    b = start;
    if (!factor.solve(b.data(), 3).ok) st.SkipWithError("solve failed");
    benchmark::DoNotOptimize(b.data());
  }
  st.counters["nnz_L"] = static_cast<double>(factor.nonZeros());
}
BENCHMARK_CAPTURE(BM_KeptFactorSolve, copy, KeptFactorWay::Copy)
    ->Arg(8)
    ->Arg(10)
    ->Arg(12)
    ->Arg(16)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_KeptFactorSolve, single, KeptFactorWay::Single)
    ->Arg(8)
    ->Arg(10)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Arg(32)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_KeptFactorSolve, cholmod, KeptFactorWay::Cholmod)
    ->Arg(8)
    ->Arg(10)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Arg(32)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
