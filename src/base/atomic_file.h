// Files are replaced atomically: the contents go to a temporary file in the same directory,
// which is flushed to disk and renamed over the target. A crash, a full disk or a missing
// directory leaves any previous file intact.
//
// What the target is decides how it is written:
//   missing             created by the rename, mode 0666 less the umask
//   a regular file      replaced by the rename, keeping its permission bits (and, as root, its
//                       owner); other hard links to it keep the previous contents
//   a symbolic link     followed to the end: the file it names is replaced as above, the link
//                       stays (a dangling link's target is created)
//   anything else       a device, FIFO or socket (/dev/null, /dev/stdout to a pipe) is written
//                       in place, without a rename: never replaced by a regular file
//   a directory         refused
//
// SIGINT, SIGTERM or SIGHUP arriving during a write, in a program that leaves them at their
// default action, removes the temporary file before the program dies (a program that handles
// them itself, like jello-sim, finishes the write).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace jello {

// Throws std::runtime_error naming the path and the system's reason.
void writeFileAtomically(const std::filesystem::path& path, std::string_view contents);

// Why writeFileAtomically(path, ...) would fail for a reason known before the contents exist
// (an empty path, a directory, a missing or unwritable directory, an unwritable special file),
// or an empty string: for programs to check every output before a long run.
std::string outputProblem(const std::filesystem::path& path);

// The file writeFileAtomically(path, ...) would write, as an absolute path with every symbolic
// link resolved (a dangling link's missing target included): two outputs that resolve to one
// file would overwrite each other. The path made absolute where its links cannot be read.
std::filesystem::path writtenFile(const std::filesystem::path& path);

namespace testing {
// Called, when set, right after the temporary file is created: a test raises a signal there.
extern void (*afterTemporaryCreated)();
}  // namespace testing

}  // namespace jello
