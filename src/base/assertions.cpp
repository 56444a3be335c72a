#include "src/base/assertions.h"

#include <cstdio>
#include <cstdlib>

namespace jello::detail {

void assertionFailed(const char* kind, const char* condition, const char* message, const char* file,
                     int line) {
  std::fprintf(stderr, "%s:%d: %s failed: %s (%s)\n", file, line, kind, condition, message);
  std::fflush(stderr);
  std::abort();
}

}  // namespace jello::detail
