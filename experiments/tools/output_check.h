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

// What checkOutputs found: nothing, an output that cannot be written (an I/O failure: exit 1),
// or two outputs naming one file (a usage error: exit 2).
enum class OutputCheck { Ok, Unwritable, SameFile };

// Whether every output can be written and no two name the same file (they would overwrite each
// other): the same path, or two that resolve to one file (./r.x and r.x, an absolute path and
// its relative form, a symlink and its target, two hard links). Prints each problem on stderr
// ("<program>: error: cannot write PATH (FLAG): why", "<program>: error: FLAG1 PATH1 and FLAG2
// PATH2 name the same file"); a same-file problem outranks an unwritable one.
OutputCheck checkOutputs(const char* program, const std::vector<PlannedOutput>& outputs);

// Whether two paths name one file: both existing with one device and inode, or one file that a
// write to either would end at (src/base/atomic_file.h, writtenFile).
bool sameFile(const std::string& a, const std::string& b);

}  // namespace jello
