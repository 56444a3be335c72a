// A progress line on standard error for long runs: silent for the first second, then updated
// about twice a second (in place on a terminal, a line every 5 s otherwise), however long one
// step takes: the clock is read every `stride` calls, the stride adapting so that it is read
// about every 10 ms (every call when steps are slow, every few thousand when they are fast).
#pragma once

#include <chrono>
#include <string>

namespace jello {

class Progress {
 public:
  // `label` names the work, e.g. "rk4 steps".
  Progress(bool enabled, std::string label);
  // Cheap to call every step (see above).
  void update(long done, long total) {
    if (enabled_ && ++calls_ >= stride_) tick(done, total);
  }
  // The same without the call counter: for callers that report rarely (grid points).
  void report(long done, long total) {
    if (enabled_) draw(done, total);
  }
  void finish();

 private:
  void draw(long done, long total);
  void tick(long done, long total);

  bool enabled_;
  std::string label_;
  bool tty_;
  bool drawn_ = false;
  unsigned long calls_ = 0, stride_ = 1;
  std::chrono::steady_clock::time_point start_, last_, lastTick_;
};

}  // namespace jello
