#include "solvers/linalg/cosine_solver.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>

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

// One column's scratch, aligned as FFTW planned for (fftw_malloc), so fftw_execute_r2r may run
// the plans on it from any thread.
struct Buffer {
  explicit Buffer(std::size_t size)
      : data(static_cast<double*>(fftw_malloc(sizeof(double) * size))) {}
  ~Buffer() { fftw_free(data); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  double* data;
};

}  // namespace

// A solve runs in three passes over the columns' n x n slabs (i fixed) and their lines along i,
// each split evenly over the threads (three columns on two threads would leave one idle half
// the time if each thread took whole columns): the 2-D transform of each slab; on each run of n
// lines along i (j fixed) the 1-D transform, the division by the eigenvalues and the inverse;
// the inverse 2-D transform of each slab.
struct CosineSolver::Plans {
  fftw_plan slab = nullptr, slabInverse = nullptr;    // one slab, n x n contiguous
  fftw_plan lines = nullptr, linesInverse = nullptr;  // n lines along i from one (j, k = 0)
  Buffer buffer;  // three columns: the solve's work, in FFTW's alignment
  explicit Plans(std::size_t size) : buffer(3 * size) {}
  ~Plans() {
    const std::lock_guard<std::mutex> lock(plannerMutex());
    for (fftw_plan p : {slab, slabInverse, lines, linesInverse}) {
      if (p) fftw_destroy_plan(p);
    }
  }
};

CosineSolver::CosineSolver(int n) : n_(n), plans_(std::make_unique<Plans>(std::size_t(n) * n * n)) {
  JELLO_ASSERT(n >= 2, "a cosine grid has at least 2 values per axis");
  double* data = plans_->buffer.data;
  const int lineLength[1] = {n};
  const std::lock_guard<std::mutex> lock(plannerMutex());
  // FFTW_MEASURE: planning times candidate plans on the scratch (tens of ms at 32^3, once a
  // process: FFTW keeps what it learned) for transforms twice as fast as FFTW_ESTIMATE's
  // (a 3-D pair at 32^3: 0.42 against 0.76 ms).
  plans_->slab = fftw_plan_r2r_2d(n, n, data, data, FFTW_REDFT10, FFTW_REDFT10, FFTW_MEASURE);
  plans_->slabInverse =
      fftw_plan_r2r_2d(n, n, data, data, FFTW_REDFT01, FFTW_REDFT01, FFTW_MEASURE);
  const fftw_r2r_kind forward[1] = {FFTW_REDFT10}, inverse[1] = {FFTW_REDFT01};
  plans_->lines = fftw_plan_many_r2r(1, lineLength, n, data, nullptr, n * n, 1, data, nullptr,
                                     n * n, 1, forward, FFTW_MEASURE);
  plans_->linesInverse = fftw_plan_many_r2r(1, lineLength, n, data, nullptr, n * n, 1, data,
                                            nullptr, n * n, 1, inverse, FFTW_MEASURE);
  JELLO_ASSERT(plans_->slab && plans_->slabInverse && plans_->lines && plans_->linesInverse,
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
  double* buffer = plans_->buffer.data;
  const double* inverse = inverse_.data();
  const Plans& plans = *plans_;
  // Pass 0: copy in and transform slabs; 1: the lines, divided; 2: inverse slabs, copy out.
  auto pass = [&](int which, std::ptrdiff_t lo, std::ptrdiff_t hi) {
    for (std::ptrdiff_t r = lo; r < hi; ++r) {
      const std::ptrdiff_t c = r / n, at = r % n;
      if (which == 1) {
        double* base = buffer + c * size + at * n;  // the lines of j = at
        fftw_execute_r2r(plans.lines, base, base);
        const double* divide = inverse + at * n;
        for (std::ptrdiff_t i = 0; i < n; ++i) {
#pragma omp simd
          for (std::ptrdiff_t k = 0; k < n; ++k) base[i * slab + k] *= divide[i * slab + k];
        }
        fftw_execute_r2r(plans.linesInverse, base, base);
        continue;
      }
      double* data = buffer + c * size + at * slab;
      double* xs = x + c * size + at * slab;
      if (which == 0) {
        std::memcpy(data, xs, sizeof(double) * std::size_t(slab));
        fftw_execute_r2r(plans.slab, data, data);
      } else {
        fftw_execute_r2r(plans.slabInverse, data, data);
        std::memcpy(xs, data, sizeof(double) * std::size_t(slab));
      }
    }
  };
  const int threads = threadsFor(size);
  for (int which = 0; which < 3; ++which) {
    if (threads <= 1) {
      pass(which, 0, runs);
      continue;
    }
    runParallel(threads, [&](int t) { pass(which, runs * t / threads, runs * (t + 1) / threads); });
  }
}

}  // namespace jello
