// Both cores for the model's large loops (README "Speed"): a small pool of worker threads that
// runs the parts of one loop at once. Only the spring forces use it, and only from
// kParallelMinPoints points up, where a loop is long enough (about a millisecond) to pay for
// waking a thread (microseconds). The pool is shared by the process: a caller that finds it busy
// (another thread's loop, an experiment's parallel grid) runs its parts itself, one after another,
// so the result never depends on who got the pool.
#pragma once

#include <functional>

namespace jello {

inline constexpr int kParallelMinPoints = 16 * 16 * 16;

// The threads a loop is split over: setParallelThreads's value if called, else the environment's
// JELLO_THREADS (1 = serial), else the CPUs this process may run on, at most 8.
int parallelThreads();
// Sets it for the whole process (tests, benchmarks): 1 makes every loop serial.
void setParallelThreads(int threads);

// Runs body(part) for part in [0, parts): part 0 on the calling thread, the others on the pool's
// workers; returns when all are done. body must not throw.
void runParallel(int parts, const std::function<void(int)>& body);

}  // namespace jello
