#include "solvers/linalg/solver_threads.h"

#include <dlfcn.h>

#include <cstdlib>
#include <fstream>
#include <mutex>

namespace jello {
namespace {

std::string settings = "libraries' defaults";

// A function of a library this process loaded, or null.
template <class F>
F loadedFunction(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_DEFAULT, name));
}

}  // namespace

void applySolverThreadSettings() {
  static std::once_flag once;
  std::call_once(once, [] {
    std::string made;
    if (!std::getenv("OPENBLAS_NUM_THREADS")) {
      if (const auto set = loadedFunction<void (*)(int)>("openblas_set_num_threads")) {
        set(1);
        made = "openblas 1 thread";
      }
    }
    if (!std::getenv("OMP_THREAD_LIMIT") && !std::getenv("OMP_NUM_THREADS")) {
      if (const auto set = loadedFunction<void (*)(int)>("omp_set_max_active_levels")) {
        set(0);
        made += std::string(made.empty() ? "" : "; ") + "openmp serial";
      }
    }
    if (!made.empty()) settings = made;
  });
}

std::string solverThreadSettings() {
  return settings;
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
