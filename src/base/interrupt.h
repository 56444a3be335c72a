// A request to stop a long computation, set from a signal handler and polled inside long steps
// (CVODE's right-hand side, Newton and projective iterations), so that Ctrl-C or SIGTERM stops
// within a fraction of a second even when one output interval takes minutes. A lock-free
// atomic: safe to set from a signal handler.
#pragma once

#include <atomic>

namespace jello {

namespace detail {
inline std::atomic<int> interruptSignal{0};
static_assert(std::atomic<int>::is_always_lock_free, "settable from a signal handler");
}  // namespace detail

// The signal that asked to stop (0: none). requestInterrupt is async-signal-safe.
inline void requestInterrupt(int signo) noexcept {
  detail::interruptSignal.store(signo, std::memory_order_relaxed);
}
inline int interruptRequested() noexcept {
  return detail::interruptSignal.load(std::memory_order_relaxed);
}
inline void clearInterrupt() noexcept {
  detail::interruptSignal.store(0, std::memory_order_relaxed);
}

}  // namespace jello
