#include "runtime_environment.h"

#include <unistd.h>

#include <csignal>
#include <cstdio>
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

void setSignalHandler(const char* program, int signo, void (*handler)(int)) {
  if (std::signal(signo, handler) == SIG_ERR) {
    std::fprintf(stderr, "%s: warning: cannot set the handler of signal %d\n", program, signo);
  }
}

}  // namespace jello
