#include "solvers/linalg/blas_headroom.h"

#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <fstream>

namespace jello {
namespace {

std::atomic<bool> passed{false};

// The process's mapped address space in bytes (/proc/self/statm's first field), or -1.
double mappedBytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = -1.0;
  if (!(statm >> pages)) return -1.0;
  return pages * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

}  // namespace

std::string blasHeadroomProblem() {
  if (passed.load(std::memory_order_relaxed)) return {};
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) {
    passed.store(true, std::memory_order_relaxed);  // no limit: nothing to check, ever
    return {};
  }
  const double mib = 1024.0 * 1024.0;
  const double used = mappedBytes();
  const double free = (static_cast<double>(limit.rlim_cur) - used) / mib;
  if (used >= 0.0 && free < kBlasHeadroomMiB) {
    char buf[480];
    std::snprintf(buf, sizeof buf,
                  "the address-space limit (ulimit -v %.0f kB) leaves %.0f MiB free; CHOLMOD's "
                  "BLAS (OpenBLAS) needs about %.0f MiB at once and would hang retrying: raise "
                  "the limit, or solve by conjugate gradients where the program offers them "
                  "(jello-sim --linear-solver cg; jello-scaling has no such choice)",
                  static_cast<double>(limit.rlim_cur) / 1024.0, free < 0.0 ? 0.0 : free,
                  kBlasHeadroomMiB);
    return buf;
  }
  // Checked here, just before the first factorization; OpenBLAS keeps its buffer afterwards.
  passed.store(true, std::memory_order_relaxed);
  return {};
}

}  // namespace jello
