// What every program does when memory runs out: a clear message and exit code 1, wherever the
// allocation failed (a world's springs, a solver's factor, a table), instead of an uncaught
// std::bad_alloc aborting with 134; and any other uncaught exception, named, exit 1. Installed
// first thing in each main().
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <system_error>

namespace jello {

namespace detail {
inline const char* outOfMemoryProgram = "jello";
inline void onOutOfMemory() {
  // Only async-safe calls: the heap cannot be trusted now.
  const char* p = outOfMemoryProgram;
  const char msg[] =
      ": error: out of memory (an allocation failed; try a smaller cube, field or grid, or a "
      "higher memory limit)\n";
  [[maybe_unused]] ssize_t a = ::write(STDERR_FILENO, p, std::strlen(p));
  [[maybe_unused]] ssize_t b = ::write(STDERR_FILENO, msg, sizeof msg - 1);
  std::_Exit(1);
}

// A std::bad_alloc nobody caught (Eigen and CHOLMOD's wrappers throw it without going through
// operator new, so the new-handler never sees them) ends the same way. Any other exception
// nobody caught (a library's, thrown where no main expected one) is named and ends with exit 1,
// never a silent SIGABRT; only a terminate without an exception (a programming error) aborts.
inline void onTerminate() {
  if (const std::exception_ptr e = std::current_exception()) {
    const char* what = "an exception of unknown type";
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      onOutOfMemory();
    } catch (const std::system_error& ex) {
      // A thread that could not be started for want of memory (its stack, under a memory
      // limit: EAGAIN) is memory running out too.
      if (ex.code() == std::errc::resource_unavailable_try_again ||
          ex.code() == std::errc::not_enough_memory) {
        onOutOfMemory();
      }
      what = ex.what();
    } catch (const std::exception& ex) {
      what = ex.what();
    } catch (...) {
    }
    const char* p = outOfMemoryProgram;
    const char head[] = ": error: unexpected failure: ";
    [[maybe_unused]] ssize_t a = ::write(STDERR_FILENO, p, std::strlen(p));
    [[maybe_unused]] ssize_t b = ::write(STDERR_FILENO, head, sizeof head - 1);
    [[maybe_unused]] ssize_t c = ::write(STDERR_FILENO, what, std::strlen(what));
    [[maybe_unused]] ssize_t d = ::write(STDERR_FILENO, "\n", 1);
    std::_Exit(1);
  }
  std::abort();
}
}  // namespace detail

inline void exitCleanlyWhenOutOfMemory(const char* program) {
  detail::outOfMemoryProgram = program;
  std::set_new_handler(detail::onOutOfMemory);
  std::set_terminate(detail::onTerminate);
}

}  // namespace jello
