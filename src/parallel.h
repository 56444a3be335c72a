// Both cores for the model's large loops (README "Speed"): a small pool of worker threads that
// runs the parts of one loop at once. Only the spring forces and energy use it, and only from
// kParallelMinPoints points up, where a loop is long enough (milliseconds) to pay for waking a
// thread and for the worker's spinning beside the step's serial rest. The pool is shared by the
// process: a caller that finds it busy (another thread's loop, an experiment's parallel grid)
// runs its parts itself, one after another.
#pragma once

#include <cstddef>
#include <functional>

namespace jello {

// Measured (experiments/results/speed_threads.json): at 16^3 the spring forces ran 1.35x faster
// on two threads but a whole RK4 step 0.87x slower (the waiting worker and the serial rest of the
// step share the VM's two CPUs); at 32^3 1.86x and 1.42x.
inline constexpr int kParallelMinPoints = 32 * 32 * 32;

// The most threads a loop is ever split over (JELLO_THREADS and setParallelThreads are clamped).
inline constexpr int kMaxParallelThreads = 64;

// The threads a loop is split over: setParallelThreads's value if called, else the environment's
// JELLO_THREADS (1 = serial), else the CPUs this process may run on, at most 8.
int parallelThreads();
// Sets it for the whole process (tests, benchmarks): 1 makes every loop serial.
void setParallelThreads(int threads);

// Runs body(part) for part in [0, parts): part 0 on the calling thread, the others on the pool's
// workers; returns when all are done. body must not throw.
void runParallel(int parts, const std::function<void(int)>& body);

// A loop over the base points [0, n) of springs (or of their matrix blocks) that writes to each
// base point and to partners at most `reach` points after it, split over `threads`: [0, n) is cut
// into `threads` runs separated by gaps of `reach` points, so no two runs write the same point,
// and body(lo, hi, owned) runs for the runs at once, then for the gaps one after another. `owned`
// ends the points the call writes first, to be set rather than added to: a run's own points and
// the gap after it, [lo, owned); none for a gap (owned == lo), whose points and reach are the
// runs' (written first by the run before it or after it, both done). One serial call (0, n, n)
// for one thread, or when runs would be no longer than the gaps. body must not throw. A
// template: the loop handed to the pool captures two references, which std::function holds
// without allocating, whatever body captures.
struct BasePointRuns {
  std::ptrdiff_t n, reach, run;  // run: each run's length; 0 when serial
  int threads;
  std::ptrdiff_t start(int t) const { return t * (run + reach); }
};
BasePointRuns splitBasePoints(std::ptrdiff_t n, std::ptrdiff_t reach, int threads);

template <class Body>
void runOverBasePoints(std::ptrdiff_t n, std::ptrdiff_t reach, int threads, const Body& body) {
  const BasePointRuns runs = splitBasePoints(n, reach, threads);
  if (runs.run == 0) {
    body(std::ptrdiff_t{0}, n, n);
    return;
  }
  runParallel(runs.threads, [&runs, &body](int t) {
    const bool last = t + 1 == runs.threads;
    body(runs.start(t), last ? runs.n : runs.start(t) + runs.run,
         last ? runs.n : runs.start(t + 1));
  });
  for (int t = 0; t + 1 < runs.threads; ++t) {
    const std::ptrdiff_t lo = runs.start(t) + runs.run;
    body(lo, runs.start(t + 1), lo);
  }
}

}  // namespace jello
