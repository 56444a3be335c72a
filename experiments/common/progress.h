// A progress line on standard error for long runs: silent for the first second, then updated
// about twice a second (in place on a terminal, a line every 5 s otherwise).
#pragma once

#include <chrono>
#include <string>

namespace jello {

class Progress {
 public:
  // `label` names the work, e.g. "rk4 steps".
  Progress(bool enabled, std::string label);
  // Cheap to call every step: looks at the clock only every 256 calls.
  void update(long done, long total) {
    if (enabled_ && (++calls_ & 255) == 0) draw(done, total);
  }
  // The same without the call counter: for callers that report rarely (grid points).
  void report(long done, long total) {
    if (enabled_) draw(done, total);
  }
  void finish();

 private:
  void draw(long done, long total);

  bool enabled_;
  std::string label_;
  bool tty_;
  bool drawn_ = false;
  unsigned long calls_ = 0;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace jello
