#include "experiments/common/progress.h"

#include <unistd.h>

#include <cstdio>

namespace jello {

Progress::Progress(bool enabled, std::string label)
    : enabled_(enabled),
      label_(std::move(label)),
      tty_(::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()),
      last_(start_),
      lastTick_(start_) {}

void Progress::draw(long done, long total) {
  using namespace std::chrono;
  const auto now = steady_clock::now();
  const double elapsed = duration<double>(now - start_).count();
  const double sinceLast = duration<double>(now - last_).count();
  // The first line after a second, then every half second (terminal) or 5 s (a log).
  if (elapsed < 1.0 || (drawn_ && sinceLast < (tty_ ? 0.5 : 5.0))) return;
  last_ = now;
  const double fraction = total > 0 ? double(done) / double(total) : 0.0;
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  const int written = std::fprintf(stderr, "%s[%3.0f%%] %ld/%ld %s, %.0f s elapsed, %.0f s left%s",
                                   tty_ ? "\r" : "", 100.0 * fraction, done, total, label_.c_str(),
                                   elapsed, eta, tty_ ? "\033[K" : "\n");
  if (written < 0 || std::fflush(stderr) != 0) {
    enabled_ = false;  // standard error is closed (EPIPE): the run goes on without a progress line
    std::clearerr(stderr);
    return;
  }
  drawn_ = true;
}

void Progress::tick(long done, long total) {
  using namespace std::chrono;
  const auto now = steady_clock::now();
  const double since = duration<double>(now - lastTick_).count();
  // Aim at a clock reading every 5-50 ms.
  if (since < 0.005 && stride_ < 65536) stride_ *= 2;
  if (since > 0.05 && stride_ > 1) stride_ /= 2;
  lastTick_ = now;
  calls_ = 0;
  draw(done, total);
}

void Progress::finish() {
  if (drawn_ && tty_) std::fputs("\n", stderr);
  drawn_ = false;
}

}  // namespace jello
