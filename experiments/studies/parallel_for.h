// Independent grid points of an experiment on all cores: task(i) for i in [0, count), with a
// progress line. The single-machine default; the tasks must not share mutable state.
#pragma once

#include <functional>
#include <string>

namespace jello::experiments {

// Runs task(i) for i in [0, count) on `jobs` threads, in order of i, with a progress line on
// standard error labelled `label` (silent when !progress). Exceptions propagate after all
// threads stop.
void parallelFor(int count, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task);

}  // namespace jello::experiments
