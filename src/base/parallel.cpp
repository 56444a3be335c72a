#include "src/base/parallel.h"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <vector>

namespace jello {

namespace {

// JELLO_THREADS's value, or 0 when it is unset or not a positive number.
int environmentThreads() {
  const char* env = std::getenv("JELLO_THREADS");
  const int t = env ? std::atoi(env) : 0;
  return t >= 1 ? std::min(t, kMaxParallelThreads) : 0;
}

// The CPUs this process may run on, at most 8.
int cpuThreads() {
  cpu_set_t set;
  int cpus = 1;
  if (sched_getaffinity(0, sizeof set, &set) == 0) cpus = CPU_COUNT(&set);
  return std::clamp(cpus, 1, 8);
}

int defaultThreads() {
  const int t = environmentThreads();
  return t > 0 ? t : cpuThreads();
}

std::atomic<int> configuredThreads{0};  // 0: not decided yet

// Workers wait for a new generation, run their part, and count themselves done. Between the
// loops of one step (an RK4 step evaluates the forces four times, its serial updates, contact
// and energy check between them) waiting threads spin for up to kSpin before they block: waking
// a blocked thread costs tens of microseconds on a VM, as much as a 16^3 loop's whole gain. The
// serial work between two 32^3 loops is longer than 20 us: a whole 32^3 RK4 step on two threads
// took 3.71-3.81 ms spinning 20 us, 3.53-3.57 ms at 100, 3.27-3.44 ms at 300, 3.21-3.33 ms at
// 1,000 (BM_Threads, medians of 5, alternating; one thread 4.58 ms). Only loops from
// kParallelMinPoints up use the pool, so smaller scenes never spin.
constexpr auto kSpin = std::chrono::microseconds(300);

template <class Done>
void spinUntil(Done done) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
  for (int i = 0; !done(); ++i) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if ((i & 63) == 63 && std::chrono::steady_clock::now() > until) return;
  }
}

class Pool {
 public:
  ~Pool() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      generation_.fetch_add(1, std::memory_order_release);
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  // False when another caller holds the pool.
  bool tryRun(int parts, const std::function<void(int)>& body) {
    std::unique_lock use(inUse_, std::try_to_lock);
    if (!use.owns_lock()) return false;
    while (static_cast<int>(workers_.size()) < parts - 1) {
      const int index = static_cast<int>(workers_.size()) + 1;
      // The worker waits for the generation after this one: the one this call is about to
      // start, however late the thread itself starts.
      const long now = generation_.load(std::memory_order_acquire);
      workers_.emplace_back([this, index, now] { work(index, now); });
    }
    body_.store(&body, std::memory_order_relaxed);
    parts_.store(parts, std::memory_order_relaxed);
    pending_.store(parts - 1, std::memory_order_relaxed);
    {
      std::lock_guard lock(mutex_);
      generation_.fetch_add(1, std::memory_order_release);
    }
    wake_.notify_all();
    body(0);
    const auto finished = [this] { return pending_.load(std::memory_order_acquire) == 0; };
    spinUntil(finished);
    if (!finished()) {
      std::unique_lock lock(mutex_);
      done_.wait(lock, finished);
    }
    return true;
  }

 private:
  void work(int index, long seen) {
    const auto moved = [&] { return generation_.load(std::memory_order_acquire) != seen; };
    while (true) {
      spinUntil(moved);
      if (!moved()) {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, moved);
      }
      seen = generation_.load(std::memory_order_acquire);
      {
        std::lock_guard lock(mutex_);
        if (stopping_) return;
      }
      if (index >= parts_.load(std::memory_order_relaxed)) continue;
      (*body_.load(std::memory_order_relaxed))(index);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
        std::lock_guard lock(mutex_);  // the caller checks `pending_` under it before waiting
        done_.notify_one();
      }
    }
  }

  std::mutex inUse_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::vector<std::thread> workers_;
  std::atomic<const std::function<void(int)>*> body_{nullptr};
  std::atomic<int> parts_{0};
  std::atomic<int> pending_{0};
  std::atomic<long> generation_{0};
  bool stopping_ = false;
};

Pool& pool() {
  static Pool instance;
  return instance;
}

}  // namespace

int parallelThreads() {
  int t = configuredThreads.load(std::memory_order_relaxed);
  if (t == 0) {
    t = defaultThreads();
    configuredThreads.store(t, std::memory_order_relaxed);
  }
  return t;
}

void setParallelThreads(int threads) {
  configuredThreads.store(std::clamp(threads, 1, kMaxParallelThreads), std::memory_order_relaxed);
}

void leaveOneCpuFree() {
  if (environmentThreads() == 0) setParallelThreads(std::max(1, cpuThreads() - 1));
}

void runParallel(int parts, const std::function<void(int)>& body) {
  if (parts > 1 && pool().tryRun(parts, body)) return;
  for (int part = 0; part < parts; ++part) body(part);
}

PointBlocks splitPointBlocks(std::ptrdiff_t n, std::ptrdiff_t reach, int threads) {
  const bool split = threads > 1 && n / threads / 2 >= reach;
  return {n, reach, split ? threads : 1};
}

}  // namespace jello
