#include "solvers/linalg/cosine_solver.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "src/base/assertions.h"
#include "src/base/parallel.h"

namespace jello {
namespace {

// FFTW's planner is not thread-safe (its execution with new arrays is): the experiments'
// grids build integrators on several threads at once.
std::mutex& plannerMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

// A solve runs in three passes over the columns' n x n slabs (i fixed) and their lines along i,
// each split evenly over the threads (three columns on two threads would leave one idle half
// the time if each thread took whole columns): the 2-D transform of each slab in place; on each
// run of n lines along i (j fixed), gathered into a thread's contiguous scratch, the 1-D
// transform, the division by the eigenvalues and the inverse; the inverse 2-D transform of each
// slab. The plans are FFTW_ESTIMATE's, on unaligned arrays: the same plan in every process, so a
// run repeats to the bit (FFTW_MEASURE times candidates and may pick another plan, with other
// rounding, run to run); on contiguous data they are what FFTW_MEASURE picks (r2cf codelets), and
// the gather does the buffering FFTW_MEASURE chose for the strided lines (a solve of three 32^3
// columns on one core, measured apart: 1.3 ms either way, 2.3 ms with ESTIMATE on strided lines).
struct CosineSolver::Plans {
  fftw_plan slab = nullptr, slabInverse = nullptr;    // one slab, n x n contiguous
  fftw_plan lines = nullptr, linesInverse = nullptr;  // n contiguous lines of n
  std::vector<std::vector<double>> scratch;           // one n x n block per thread
  ~Plans() {
    const std::lock_guard<std::mutex> lock(plannerMutex());
    for (fftw_plan p : {slab, slabInverse, lines, linesInverse}) {
      if (p) fftw_destroy_plan(p);
    }
  }
};

CosineSolver::CosineSolver(int n) : n_(n), plans_(std::make_unique<Plans>()) {
  JELLO_ASSERT(n >= 2, "a cosine grid has at least 2 values per axis");
  std::vector<double> data(std::size_t(n) * n);  // planning leaves it alone (FFTW_ESTIMATE)
  const int length[1] = {n};
  const fftw_r2r_kind forward[1] = {FFTW_REDFT10}, inverse[1] = {FFTW_REDFT01};
  const unsigned flags = FFTW_ESTIMATE | FFTW_UNALIGNED;
  const std::lock_guard<std::mutex> lock(plannerMutex());
  Plans& p = *plans_;
  p.slab = fftw_plan_r2r_2d(n, n, data.data(), data.data(), FFTW_REDFT10, FFTW_REDFT10, flags);
  p.slabInverse =
      fftw_plan_r2r_2d(n, n, data.data(), data.data(), FFTW_REDFT01, FFTW_REDFT01, flags);
  p.lines = fftw_plan_many_r2r(1, length, n, data.data(), nullptr, 1, n, data.data(), nullptr, 1, n,
                               forward, flags);
  p.linesInverse = fftw_plan_many_r2r(1, length, n, data.data(), nullptr, 1, n, data.data(),
                                      nullptr, 1, n, inverse, flags);
  JELLO_ASSERT(p.slab && p.slabInverse && p.lines && p.linesInverse,
               "FFTW planned the cosine transforms");
}

CosineSolver::~CosineSolver() = default;

StepResult CosineSolver::setEigenvalues(const std::vector<double>& lambda) {
  const std::size_t size = std::size_t(n_) * n_ * n_;
  JELLO_ASSERT(lambda.size() == size, "one eigenvalue per grid value");
  const double scale = std::pow(2.0 * n_, 3);
  std::vector<double> inverse(size);
  for (std::size_t i = 0; i < size; ++i) {
    if (!(lambda[i] > 0.0) || !std::isfinite(lambda[i])) {
      return StepResult::failure("cosine solver: eigenvalue " + std::to_string(i) + " is " +
                                 std::to_string(lambda[i]) + ", not positive");
    }
    inverse[i] = 1.0 / (lambda[i] * scale);
  }
  inverse_ = std::move(inverse);
  return StepResult::success();
}

void CosineSolver::solve(double* x, int columns) {
  JELLO_ASSERT(!inverse_.empty(), "eigenvalues set before a solve");
  JELLO_ASSERT(columns >= 1 && columns <= 3, "one to three columns");
  const std::ptrdiff_t n = n_, slab = n * n, size = slab * n;
  const std::ptrdiff_t runs = columns * n;  // slabs, and runs of lines: one per (column, i or j)
  const double* inverse = inverse_.data();
  Plans& plans = *plans_;
  const int threads = threadsFor(size);
  if (plans.scratch.size() < std::size_t(threads)) {
    plans.scratch.resize(std::size_t(threads), std::vector<double>(std::size_t(slab)));
  }
  // Pass 0: transform slabs; 1: the lines, divided; 2: inverse slabs.
  auto pass = [&](int which, int thread, std::ptrdiff_t lo, std::ptrdiff_t hi) {
    double* t = plans.scratch[std::size_t(thread)].data();
    for (std::ptrdiff_t r = lo; r < hi; ++r) {
      const std::ptrdiff_t c = r / n, at = r % n;
      if (which != 1) {
        double* data = x + c * size + at * slab;
        fftw_execute_r2r(which == 0 ? plans.slab : plans.slabInverse, data, data);
        continue;
      }
      double* base = x + c * size + at * n;  // the lines of j = at: base[i slab + k]
      const double* divide = inverse + at * n;
      for (std::ptrdiff_t i = 0; i < n; ++i) {
        for (std::ptrdiff_t k = 0; k < n; ++k) t[k * n + i] = base[i * slab + k];
      }
      fftw_execute_r2r(plans.lines, t, t);
      for (std::ptrdiff_t i = 0; i < n; ++i) {
        for (std::ptrdiff_t k = 0; k < n; ++k) t[k * n + i] *= divide[i * slab + k];
      }
      fftw_execute_r2r(plans.linesInverse, t, t);
      for (std::ptrdiff_t i = 0; i < n; ++i) {
        for (std::ptrdiff_t k = 0; k < n; ++k) base[i * slab + k] = t[k * n + i];
      }
    }
  };
  for (int which = 0; which < 3; ++which) {
    if (threads <= 1) {
      pass(which, 0, 0, runs);
      continue;
    }
    runParallel(threads,
                [&](int t) { pass(which, t, runs * t / threads, runs * (t + 1) / threads); });
  }
}

}  // namespace jello
