// Both cores for the model's large loops (experiments/bench/README.md): a small pool of worker
// threads that runs the parts of one loop at once. The model's forces (with an explicit step's
// updates fused in, Model::acceleration), the springs' energy, the simulation's per-step checks and
// the implicit solvers' matrix-free product use it, the model only from kParallelMinPoints points
// up, where a loop is long enough (milliseconds) to pay for waking a thread and for the
// worker's spinning beside the step's serial rest. The pool is shared by the
// process: a caller that finds it busy (another thread's loop, an experiment's parallel grid)
// runs its parts itself, one after another.
#pragma once

#include <cstddef>
#include <functional>
#include <type_traits>

namespace jello {

// From 16^3 (BM_Threads, experiments/results/speed_threads.json): with each thread running the
// whole evaluation and the integrator's update on its own block (runOverPointBlocks), a 16^3 RK4
// step is no longer slower on two threads (it was 0.87x when only the springs were split) and
// its spring forces gain 1.5x; at 8^3 a loop takes a few microseconds, as long as waking and
// joining a thread.
inline constexpr int kParallelMinPoints = 16 * 16 * 16;

// The most threads a loop is ever split over (JELLO_THREADS and setParallelThreads are clamped).
inline constexpr int kMaxParallelThreads = 64;

// The threads a loop is split over: setParallelThreads's value if called, else the environment's
// JELLO_THREADS (1 = serial), else the CPUs this process may run on, at most 8.
int parallelThreads();
// Sets it for the whole process (tests, benchmarks): 1 makes every loop serial.
void setParallelThreads(int threads);
// The threads a loop over `points` points is split over: parallelThreads() from
// kParallelMinPoints up, else 1.
inline int threadsFor(std::ptrdiff_t points) {
  return points >= kParallelMinPoints ? parallelThreads() : 1;
}
// Unless JELLO_THREADS is set, splits loops over one CPU fewer than the process may run on (at
// least one): for a program whose other thread is busy all the time, as the viewer's drawing is.
// A loop's parts wait for each other, so a part whose CPU the other thread holds stalls them all:
// on two CPUs the viewer simulated a 16^3 cube with RK4 many times slower on two threads than on
// one (experiments/results/viewer_fps.json).
void leaveOneCpuFree();

// Runs body(part) for part in [0, parts): part 0 on the calling thread, the others on the pool's
// workers; returns when all are done. body must not throw.
void runParallel(int parts, const std::function<void(int)>& body);

// A loop over the base points [0, n) of springs (or of their matrix blocks) that writes to each
// base point and to partners at most `reach` points after it, split over threads with no serial
// part. Thread t owns the points [begin(t), end(t)), cut in halves at middle(t); the work runs in
// two phases, the threads of each at once.
//   Phase 0: each thread first sets (rather than adds to) the points only it writes in this
//   phase, [setBegin(t), setEnd(t)): its block but its first `reach` points, and the next
//   block's first `reach` points; then it runs the base points of its second half, whose writes
//   reach the next block's first `reach` points at most.
//   Phase 1: each thread runs the base points of its first half, whose writes stay in its block;
//   after that every write to its block is done, and after(begin(t), end(t)) runs there.
// One thread (serial) when a half would be shorter than reach.
struct PointBlocks {
  std::ptrdiff_t n, reach;
  int threads;
  std::ptrdiff_t begin(int t) const { return n * t / threads; }
  std::ptrdiff_t end(int t) const { return n * (t + 1) / threads; }
  std::ptrdiff_t middle(int t) const { return (begin(t) + end(t)) / 2; }
  std::ptrdiff_t setBegin(int t) const { return t == 0 ? 0 : begin(t) + reach; }
  std::ptrdiff_t setEnd(int t) const { return t + 1 == threads ? n : end(t) + reach; }
};
PointBlocks splitPointBlocks(std::ptrdiff_t n, std::ptrdiff_t reach, int threads);

// Runs the phases above: body(setLo, setHi, lo, hi) sets the points [setLo, setHi) and then adds
// the terms of the base points [lo, hi); after(lo, hi) follows on each block once it is done.
// Serial: body(0, n, 0, n), after(0, n). Neither may throw. A template: the loops handed to the
// pool capture at most two references, which std::function holds without allocating.
template <class Body, class After>
void runOverPointBlocks(const PointBlocks& blocks, const Body& body, const After& after) {
  if (blocks.threads == 1) {
    body(std::ptrdiff_t{0}, blocks.n, std::ptrdiff_t{0}, blocks.n);
    after(std::ptrdiff_t{0}, blocks.n);
    return;
  }
  runParallel(blocks.threads, [&blocks, &body](int t) {
    body(blocks.setBegin(t), blocks.setEnd(t), blocks.middle(t), blocks.end(t));
  });
  const auto firstHalves = [&blocks, &body, &after](int t) {
    body(blocks.begin(t), blocks.begin(t), blocks.begin(t), blocks.middle(t));
    after(blocks.begin(t), blocks.end(t));
  };
  runParallel(blocks.threads, [&firstHalves](int t) { firstHalves(t); });
}

// A reference to a callable body(lo, hi) over a range of points, for a function that is not a
// template to take a lambda (std::function would allocate for one that captures much). The
// callable must outlive the call.
class PointRangeRef {
 public:
  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, PointRangeRef>>>
  PointRangeRef(const F& body)  // NOLINT(google-explicit-constructor): taken as an argument
      : body_(&body), call_([](const void* b, std::ptrdiff_t lo, std::ptrdiff_t hi) {
          (*static_cast<const F*>(b))(lo, hi);
        }) {}
  void operator()(std::ptrdiff_t lo, std::ptrdiff_t hi) const { call_(body_, lo, hi); }

 private:
  const void* body_;
  void (*call_)(const void*, std::ptrdiff_t, std::ptrdiff_t);
};

}  // namespace jello
