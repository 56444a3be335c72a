// Signal handling of the command-line programs (jello-sim, jello-create-world).
#pragma once

namespace jello {

// std::signal with its result checked: on failure it warns on stderr, naming `program`.
void setSignalHandler(const char* program, int signo, void (*handler)(int));

}  // namespace jello
