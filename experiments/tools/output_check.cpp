#include "experiments/tools/output_check.h"

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "src/base/atomic_file.h"

namespace jello {

bool sameFile(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  if (a.empty() || b.empty()) return false;
  if (a == b) return true;
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;  // both exist: one device and inode
  return writtenFile(a) == writtenFile(b);
}

OutputCheck checkOutputs(const char* program, const std::vector<PlannedOutput>& outputs) {
  OutputCheck result = OutputCheck::Ok;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const PlannedOutput& o = outputs[i];
    if (const std::string why = outputProblem(o.path); !why.empty()) {
      std::fprintf(stderr, "%s: error: cannot write %s (%s): %s\n", program, o.path.c_str(), o.flag,
                   why.c_str());
      if (result == OutputCheck::Ok) result = OutputCheck::Unwritable;
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (sameFile(o.path, outputs[j].path)) {
        std::fprintf(stderr, "%s: error: %s %s and %s %s name the same file\n", program,
                     outputs[j].flag, outputs[j].path.c_str(), o.flag, o.path.c_str());
        result = OutputCheck::SameFile;
      }
    }
  }
  return result;
}

}  // namespace jello
