// Signal handling of the command-line programs (jello-sim, jello-create-world).
#pragma once

namespace jello {

// std::signal with its result checked: on failure it warns on stderr, naming `program`.
void setSignalHandler(const char* program, int signo, void (*handler)(int));

// A closed standard error (`... 2>&1 | head -c 1`) must not kill a run: SIGPIPE is ignored,
// so a write to it fails with EPIPE instead, which the progress line notices and stops on.
void ignoreBrokenPipes(const char* program);

}  // namespace jello
