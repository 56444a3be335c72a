#include "src/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace jello {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int err) {
  throw std::runtime_error("cannot write " + path.string() + ": " + what + ": " +
                           std::strerror(err));
}

// Closes and removes the temporary file unless it was renamed into place.
class TempFile {
 public:
  explicit TempFile(std::string name) : name_(std::move(name)) { fd_ = ::mkstemp(name_.data()); }
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!committed_) ::unlink(name_.c_str());
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
};

}  // namespace

void writeFileAtomically(const std::filesystem::path& path, std::string_view contents) {
  TempFile tmp(path.string() + ".tmp.XXXXXX");
  if (tmp.fd() < 0) fail(path, "cannot create a temporary file beside it", errno);

  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (::fchmod(tmp.fd(), 0666 & ~mask) != 0) fail(path, "fchmod", errno);

  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(tmp.fd(), data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail(path, "write", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(tmp.fd()) != 0) fail(path, "fsync", errno);
  if (tmp.close() != 0) fail(path, "close", errno);
  if (::rename(tmp.name().c_str(), path.c_str()) != 0) fail(path, "rename", errno);
  tmp.commit();
}

}  // namespace jello
