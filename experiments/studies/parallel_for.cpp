#include "experiments/studies/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <numeric>
#include <thread>
#include <vector>

#include "experiments/common/progress.h"
#include "experiments/studies/csv_table.h"
#include "src/base/parallel.h"

namespace jello::experiments {

void parallelFor(const std::vector<int>& tasks, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task) {
  const int count = int(tasks.size());
  std::atomic<int> next{0}, done{0};
  std::exception_ptr failure;
  std::mutex failureMutex;
  const auto worker = [&] {
    for (int i; (i = next.fetch_add(1)) < count;) {
      {
        std::lock_guard lock(failureMutex);
        if (failure) return;
      }
      try {
        const int index = tasks[static_cast<std::size_t>(i)];
        const TaskScope scope(index);
        task(index);
      } catch (...) {
        std::lock_guard lock(failureMutex);
        if (!failure) failure = std::current_exception();
      }
      ++done;
    }
  };
  const int modelThreads = parallelThreads();
  if (jobs > 1) setParallelThreads(1);
  std::vector<std::thread> threads;
  for (int t = 1; t < std::max(1, jobs); ++t) threads.emplace_back(worker);
  // The calling thread works too, and draws the progress line between its tasks.
  Progress bar(progress, label);
  std::thread reporter;
  std::atomic<bool> finished{false};
  if (progress) {
    reporter = std::thread([&] {
      while (!finished) {
        bar.report(done, count);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    });
  }
  worker();
  for (std::thread& t : threads) t.join();
  finished = true;
  if (reporter.joinable()) reporter.join();
  bar.finish();
  setParallelThreads(modelThreads);
  if (failure) std::rethrow_exception(failure);
}

void parallelFor(int count, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task) {
  std::vector<int> tasks(static_cast<std::size_t>(std::max(0, count)));
  std::iota(tasks.begin(), tasks.end(), 0);
  parallelFor(tasks, jobs, label, progress, task);
}

}  // namespace jello::experiments
