#include "experiments/tools/output_check.h"

#include <cstdio>

#include "src/base/atomic_file.h"

namespace jello {

bool checkOutputs(const char* program, const std::vector<PlannedOutput>& outputs) {
  bool ok = true;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const PlannedOutput& o = outputs[i];
    if (const std::string why = outputProblem(o.path); !why.empty()) {
      std::fprintf(stderr, "%s: error: cannot write %s (%s): %s\n", program, o.path.c_str(), o.flag,
                   why.c_str());
      ok = false;
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!o.path.empty() && o.path == outputs[j].path) {
        std::fprintf(stderr, "%s: error: %s and %s name the same file %s\n", program,
                     outputs[j].flag, o.flag, o.path.c_str());
        ok = false;
      }
    }
  }
  return ok;
}

}  // namespace jello
