#include "src/base/atomic_file.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace jello {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int err) {
  throw std::runtime_error("cannot write " + path.string() + ": " + what + ": " +
                           std::strerror(err));
}

// Temporary files being written, for a fatal signal to remove (async-signal-safe: fixed slots,
// each published by an atomic flag once its name is in place).
constexpr std::size_t kSlots = 8;
constexpr std::size_t kNameBytes = 4096;
struct Slot {
  std::atomic<bool> used{false};
  std::atomic<bool> ready{false};
  char name[kNameBytes] = {};
};
std::array<Slot, kSlots> slots;

constexpr std::array<int, 3> kFatalSignals = {SIGINT, SIGTERM, SIGHUP};

// Removes every registered temporary file, then dies of the signal as it would have.
extern "C" void removeTemporariesAndDie(int signo) {
  for (Slot& slot : slots) {
    if (slot.ready.load()) ::unlink(slot.name);
  }
  std::signal(signo, SIG_DFL);
  std::raise(signo);
}

// While any file is being written, SIGINT, SIGTERM and SIGHUP whose action is the default (to
// die) remove the temporary files first. A program's own handlers (jello-sim stops and still
// writes its outputs) are left alone.
class CleanupOnSignals {
 public:
  CleanupOnSignals() {
    const std::lock_guard<std::mutex> lock(mutex);
    if (users++ > 0) return;
    for (std::size_t i = 0; i < kFatalSignals.size(); ++i) {
      struct sigaction current {};
      installed[i] = ::sigaction(kFatalSignals[i], nullptr, &current) == 0 &&
                     !(current.sa_flags & SA_SIGINFO) && current.sa_handler == SIG_DFL &&
                     std::signal(kFatalSignals[i], removeTemporariesAndDie) != SIG_ERR;
    }
  }
  ~CleanupOnSignals() {
    const std::lock_guard<std::mutex> lock(mutex);
    if (--users > 0) return;
    for (std::size_t i = 0; i < kFatalSignals.size(); ++i) {
      if (installed[i]) std::signal(kFatalSignals[i], SIG_DFL);
    }
  }
  CleanupOnSignals(const CleanupOnSignals&) = delete;
  CleanupOnSignals& operator=(const CleanupOnSignals&) = delete;

 private:
  static inline std::mutex mutex;
  static inline int users = 0;
  static inline std::array<bool, kFatalSignals.size()> installed = {};
};

// Closes and removes the temporary file unless it was renamed into place.
class TempFile {
 public:
  explicit TempFile(std::string name) : name_(std::move(name)) {
    fd_ = ::mkstemp(name_.data());
    if (fd_ < 0 || name_.size() >= kNameBytes) return;
    for (Slot& slot : slots) {
      bool expected = false;
      if (slot.used.compare_exchange_strong(expected, true)) {
        std::memcpy(slot.name, name_.c_str(), name_.size() + 1);
        slot.ready.store(true);
        slot_ = &slot;
        break;
      }
    }
  }
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(name_.c_str());
    if (slot_ != nullptr) {
      slot_->ready.store(false);
      slot_->used.store(false);
    }
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  int fd() const { return fd_; }
  const std::string& name() const { return name_; }
  int close() {
    const int rc = ::close(fd_);
    fd_ = -1;
    return rc;
  }
  void commit() { committed_ = true; }

 private:
  std::string name_;
  int fd_ = -1;
  bool committed_ = false;
  Slot* slot_ = nullptr;
};

void writeAll(const std::filesystem::path& path, int fd, std::string_view contents) {
  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(path, "write", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
}

// "10 s": how long a FIFO was waited for.
std::string waited(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", seconds);
  return text;
}

// A device or FIFO: written where it is, as a shell redirection would. A FIFO nobody reads
// (open fails with ENXIO when non-blocking) is waited for, then refused: a blocking open waited
// forever.
void writeInPlace(const std::filesystem::path& path, std::string_view contents) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(testing::fifoWaitSeconds);
  int fd = -1;
  while ((fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK)) < 0 &&
         errno == ENXIO && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (fd < 0 && errno == ENXIO) {
    throw std::runtime_error("cannot write " + path.string() +
                             ": it is a FIFO that no process reads (waited " +
                             waited(testing::fifoWaitSeconds) + ")");
  }
  if (fd < 0) fail(path, "open", errno);
  // Written blocking, as a redirection is: a reader that is slow is waited for.
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
    const int err = errno;
    ::close(fd);
    fail(path, "fcntl", err);
  }
  try {
    writeAll(path, fd, contents);
  } catch (...) {
    ::close(fd);
    throw;
  }
  if (::close(fd) != 0) fail(path, "close", errno);
}

// The file a chain of symbolic links ends at (the path itself when it is no link). A dangling
// link resolves to the missing file it names, which the rename then creates.
std::filesystem::path followLinks(const std::filesystem::path& path) {
  std::filesystem::path target = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(target.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return target;
    std::string link(static_cast<std::size_t>(st.st_size > 0 ? st.st_size : 4096) + 1, '\0');
    const ssize_t n = ::readlink(target.c_str(), link.data(), link.size());
    if (n < 0) fail(path, "readlink", errno);
    link.resize(static_cast<std::size_t>(n));
    const std::filesystem::path next(link);
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  fail(path, "resolving its symbolic links", ELOOP);
}

}  // namespace

namespace testing {
void (*afterTemporaryCreated)() = nullptr;
double fifoWaitSeconds = kFifoWaitSeconds;
}  // namespace testing

void writeFileAtomically(const std::filesystem::path& path, std::string_view contents) {
  struct stat existing {};
  const bool exists = ::stat(path.c_str(), &existing) == 0;  // follows links
  if (!exists && errno != ENOENT) fail(path, "stat", errno);
  if (exists && S_ISDIR(existing.st_mode)) fail(path, "the target", EISDIR);
  if (exists && !S_ISREG(existing.st_mode)) {
    writeInPlace(path, contents);
    return;
  }
  const std::filesystem::path target = followLinks(path);

  const CleanupOnSignals cleanup;
  TempFile tmp(target.string() + ".tmp.XXXXXX");
  if (tmp.fd() < 0) fail(path, "cannot create a temporary file beside it", errno);
  if (testing::afterTemporaryCreated != nullptr) testing::afterTemporaryCreated();
  if (exists) {
    if (::fchmod(tmp.fd(), existing.st_mode & 07777) != 0) fail(path, "fchmod", errno);
    if (::geteuid() == 0 && ::fchown(tmp.fd(), existing.st_uid, existing.st_gid) != 0) {
      fail(path, "fchown", errno);
    }
  } else {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    if (::fchmod(tmp.fd(), 0666 & ~mask) != 0) fail(path, "fchmod", errno);
  }
  writeAll(path, tmp.fd(), contents);
  if (::fsync(tmp.fd()) != 0) fail(path, "fsync", errno);
  if (tmp.close() != 0) fail(path, "close", errno);
  if (::rename(tmp.name().c_str(), target.c_str()) != 0) fail(path, "rename", errno);
  tmp.commit();
}

std::filesystem::path writtenFile(const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::path file = std::filesystem::absolute(path, ec);
  if (ec) return path;
  try {
    file = followLinks(file);
  } catch (const std::exception&) {
    return file;  // a loop or an unreadable link: the write itself reports it
  }
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(file, ec);
  return ec ? file : canonical;
}

std::string outputProblem(const std::filesystem::path& path) {
  if (path.empty()) return "the output path is empty";
  std::error_code ec;
  const std::filesystem::path target = std::filesystem::weakly_canonical(path, ec);
  const std::filesystem::path& file = ec ? path : target;
  const auto status = std::filesystem::status(file, ec);
  if (std::filesystem::is_directory(status)) return "it is a directory";
  if (std::filesystem::is_socket(status)) {
    return "it is a socket (an output may be a file, a device or a FIFO)";
  }
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    // A device or FIFO is written in place.
    return ::access(file.c_str(), W_OK) == 0 ? "" : std::strerror(errno);
  }
  std::filesystem::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  if (!std::filesystem::is_directory(dir, ec)) {
    return "the directory " + dir.string() + " does not exist";
  }
  // The temporary file is created in the directory, then renamed: it must be writable.
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    return "the directory " + dir.string() + " is not writable (" + std::strerror(errno) + ")";
  }
  return "";
}

FifoReadHold::FifoReadHold(const std::filesystem::path& path) {
  const double seconds = testing::fifoWaitSeconds;
  std::error_code ec;
  if (!std::filesystem::is_fifo(std::filesystem::status(path, ec))) return;
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) {
    problem_ = std::string("cannot open: ") + std::strerror(errno);
    return;
  }
  // Until a writer opens it, poll() reports nothing (no POLLHUP either): wait for POLLIN (data)
  // or POLLHUP (a writer came and went).
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>(seconds * 1000.0);
  int ready = 0;
  while ((ready = ::poll(&p, 1, ms)) < 0 && errno == EINTR) {
  }
  if (ready <= 0) {
    problem_ = "it is a FIFO that no process writes (waited " + waited(seconds) + ")";
  }
}

FifoReadHold::~FifoReadHold() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace jello
