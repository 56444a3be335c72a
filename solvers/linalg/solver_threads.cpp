#include "solvers/linalg/solver_threads.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <initializer_list>

namespace jello {

void applySolverThreadSettings(char** argv) {
  bool changed = false;
  for (const char* name : {"OMP_THREAD_LIMIT", "OPENBLAS_NUM_THREADS"}) {
    if (!std::getenv(name)) changed |= ::setenv(name, "1", 0) == 0;
  }
  if (!std::getenv("OMP_WAIT_POLICY")) changed |= ::setenv("OMP_WAIT_POLICY", "passive", 0) == 0;
  if (changed) ::execv("/proc/self/exe", argv);  // returns only on failure: run as we are
}

std::string loadedBlas() {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    for (const char* name : {"libopenblas", "libblis", "libmkl", "libblas.so"}) {
      if (line.find(name) != std::string::npos) return line.substr(line.find('/'));
    }
  }
  return "none loaded";
}

}  // namespace jello
