// Numerical failure is a result the caller must look at, never an exception or a silent NaN.
#pragma once

#include <string>

namespace jello {

struct [[nodiscard]] StepResult {
  bool ok = true;
  std::string message;  // why, when !ok
  // Not a failure of the numerics: a stop was requested (src/interrupt.h) inside the step,
  // which left the state as it was before the step.
  bool interrupted = false;

  static StepResult success() { return {}; }
  static StepResult failure(std::string why) { return {false, std::move(why), false}; }
  static StepResult interruption() { return {false, "interrupted", true}; }
};

}  // namespace jello
