#include "runtime_environment.h"

#include <unistd.h>

#include <cstdlib>
#include <initializer_list>

namespace jello {

void applyRuntimeEnvironment(char** argv) {
  bool changed = false;
  for (const char* name : {"OMP_THREAD_LIMIT", "OPENBLAS_NUM_THREADS"}) {
    if (!std::getenv(name)) changed |= ::setenv(name, "1", 0) == 0;
  }
  if (!std::getenv("OMP_WAIT_POLICY")) changed |= ::setenv("OMP_WAIT_POLICY", "passive", 0) == 0;
  if (changed) ::execv("/proc/self/exe", argv);  // returns only on failure: run as we are
}

}  // namespace jello
