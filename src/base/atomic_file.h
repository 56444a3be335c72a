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
//   anything else       a device or FIFO (/dev/null, /dev/stdout to a pipe) is written in
//                       place, without a rename: never replaced by a regular file; a FIFO no
//                       process reads is waited for kFifoWaitSeconds, then refused (it blocked
//                       forever); a socket is refused (nothing can open it)
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

// How long a FIFO is waited for its other end (a reader of an output, a writer of an input).
inline constexpr double kFifoWaitSeconds = 10.0;

// Opening a FIFO for reading blocks until a process opens it for writing, forever if none
// does. Made for a path about to be read: when it is a FIFO, waits up to `seconds` for data or
// a writer and holds a non-blocking read end open, so that the caller's own open returns at
// once and nothing written is lost; problem() says why it cannot be read (no writer came).
// Nothing for any other file.
class FifoReadHold {
 public:
  explicit FifoReadHold(const std::filesystem::path& path);
  ~FifoReadHold();
  FifoReadHold(const FifoReadHold&) = delete;
  FifoReadHold& operator=(const FifoReadHold&) = delete;
  const std::string& problem() const { return problem_; }

 private:
  int fd_ = -1;
  std::string problem_;
};

namespace testing {
// Called, when set, right after the temporary file is created: a test raises a signal there.
extern void (*afterTemporaryCreated)();
// How long a FIFO's other end is waited for: kFifoWaitSeconds, shorter in tests.
extern double fifoWaitSeconds;
}  // namespace testing

}  // namespace jello
