// Independent grid points of an experiment on all cores: task(i) for each task index, with a
// progress line. The single-machine default; the tasks must not share mutable state.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace jello::experiments {

// Runs task(i) for each i of `tasks` on `jobs` threads, in the order given, with a progress
// line on standard error labelled `label` (silent when !progress). Each call runs inside a
// TaskScope(i) (csv_table.h), so the rows it adds are ordered by i. Exceptions propagate after
// all threads stop. With jobs > 1 the model's loops stay on their task's thread meanwhile
// (setParallelThreads(1), restored after): every job holds a CPU, and a loop split over threads
// would wait for a part whose CPU another job holds (src/base/parallel.h, leaveOneCpuFree).
void parallelFor(const std::vector<int>& tasks, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task);
// The same for i in [0, count).
void parallelFor(int count, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task);

}  // namespace jello::experiments
