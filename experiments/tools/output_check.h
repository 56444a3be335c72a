// The files a command-line program will write, checked before its run: a bad output path must
// not be found after an hour of simulation.
#pragma once

#include <string>
#include <vector>

namespace jello {

struct PlannedOutput {
  const char* flag;  // the option that names it, for messages ("--stats")
  std::string path;
};

// True when every output can be written and no two name the same file (they would overwrite
// each other). Otherwise prints each problem on stderr ("<program>: error: cannot write PATH
// (FLAG): why", "<program>: error: FLAG1 and FLAG2 name the same file PATH") and returns false.
bool checkOutputs(const char* program, const std::vector<PlannedOutput>& outputs);

}  // namespace jello
