// Numerical failure is a result the caller must look at, never an exception or a silent NaN.
#pragma once

#include <string>

namespace jello {

struct [[nodiscard]] StepResult {
  bool ok = true;
  std::string message;  // why, when !ok

  static StepResult success() { return {}; }
  static StepResult failure(std::string why) { return {false, std::move(why)}; }
};

}  // namespace jello
