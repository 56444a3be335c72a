// Numerical failure is a result the caller must look at, never an exception or a silent NaN.
#pragma once

#include <string>

namespace jello {

struct [[nodiscard]] StepResult {
  bool ok = true;
  std::string message;  // why, when !ok
  // Not a failure of the numerics: a stop was requested (src/base/interrupt.h) inside the step,
  // which left the state as it was before the step.
  bool interrupted = false;
  // Not a failure of the numerics either: a resource the step needs is missing (the
  // address-space limit leaves the BLAS no room); the state is left as it was before the step.
  bool resource = false;
  // A success whose equations were not solved to the integrator's tolerance (Newton at its
  // iteration cap after every retry): accepted and counted; callers that must not accept it
  // (jello-sim --strict) stop here.
  bool unconverged = false;

  static StepResult success() { return {}; }
  static StepResult unconvergedSuccess() {
    StepResult r;
    r.unconverged = true;
    return r;
  }
  static StepResult failure(std::string why) { return {false, std::move(why), false}; }
  static StepResult interruption() { return {false, "interrupted", true}; }
  static StepResult resourceFailure(std::string why) {
    return {false, std::move(why), false, true};
  }
  // A finished step's result: a success with a sub-step accepted unconverged is counted in
  // `count` and flagged; anything else is returned as it is.
  static StepResult counted(StepResult res, bool unconverged, long& count) {
    if (!res.ok || !unconverged) return res;
    ++count;
    return unconvergedSuccess();
  }
  // The same result, its message prefixed with what failed.
  StepResult within(const std::string& what) const {
    StepResult r = *this;
    r.message = what + ": " + message;
    return r;
  }
};

}  // namespace jello
