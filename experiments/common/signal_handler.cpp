#include "experiments/common/signal_handler.h"

#include <csignal>
#include <cstdio>

namespace jello {

void setSignalHandler(const char* program, int signo, void (*handler)(int)) {
  if (std::signal(signo, handler) == SIG_ERR) {
    std::fprintf(stderr, "%s: warning: cannot set the handler of signal %d\n", program, signo);
  }
}

void ignoreBrokenPipes(const char* program) {
  setSignalHandler(program, SIGPIPE, SIG_IGN);
}

}  // namespace jello
