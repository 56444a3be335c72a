#include "runtime_environment.h"

#include <unistd.h>

#include <cstdlib>

namespace jello {

void applyRuntimeEnvironment(char** argv, bool pinBlas) {
  bool changed = false;
  if (!std::getenv("OMP_WAIT_POLICY")) {
    changed |= ::setenv("OMP_WAIT_POLICY", "passive", 0) == 0;
  }
  if (pinBlas && !std::getenv("OPENBLAS_NUM_THREADS")) {
    changed |= ::setenv("OPENBLAS_NUM_THREADS", "1", 0) == 0;
  }
  if (changed) ::execv("/proc/self/exe", argv);  // returns only on failure: run as we are
}

}  // namespace jello
