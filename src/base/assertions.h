// Programming-error checks, the first of the three tiers of errors (src/ARCHITECTURE.md):
//   JELLO_ASSERT(condition, "what must hold")   on in debug and asan builds (JELLO_ASSERTIONS)
//   JELLO_VALIDATE(condition, "what must hold") costly checks (JELLO_VALIDATE): symmetric
//                                               Jacobians, finite states into every step
// A failed check prints the file, line, condition and message on stderr and aborts, so a test
// that trips one fails. Off, neither evaluates its condition. Numerical failure and bad input
// are not programming errors: they are results and messages, never these.
#pragma once

namespace jello::detail {

[[noreturn]] void assertionFailed(const char* kind, const char* condition, const char* message,
                                  const char* file, int line);

}  // namespace jello::detail

// On: the condition, and a failure report naming it. Off: not evaluated, but still compiled.
#define JELLO_DETAIL_CHECK(kind, condition, message) \
  ((condition) ? static_cast<void>(0)                \
               : ::jello::detail::assertionFailed(kind, #condition, message, __FILE__, __LINE__))
#define JELLO_DETAIL_UNCHECKED(condition) static_cast<void>(sizeof(!(condition)))

#if defined(JELLO_ENABLE_ASSERTIONS)
inline constexpr bool kJelloAssertions = true;
#define JELLO_ASSERT(condition, message) JELLO_DETAIL_CHECK("assertion", condition, message)
#else
inline constexpr bool kJelloAssertions = false;
#define JELLO_ASSERT(condition, message) JELLO_DETAIL_UNCHECKED(condition)
#endif

#if defined(JELLO_ENABLE_VALIDATION)
inline constexpr bool kJelloValidate = true;
#define JELLO_VALIDATE(condition, message) JELLO_DETAIL_CHECK("validation", condition, message)
#else
inline constexpr bool kJelloValidate = false;
#define JELLO_VALIDATE(condition, message) JELLO_DETAIL_UNCHECKED(condition)
#endif
