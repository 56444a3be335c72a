#include "viewer/video_writer.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "src/base/atomic_file.h"

extern char** environ;

namespace jello::viewer {
namespace {

// The ffmpeg on PATH, or empty.
std::string findFfmpeg() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path candidate =
        std::filesystem::path(dirs.substr(start, end - start)) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    start = end + 1;
  }
  return "";
}

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& why) {
  throw std::runtime_error("cannot write the video " + path.string() + ": " + why);
}

std::string format(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace

std::string VideoWriter::problem(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext != ".mp4" && ext != ".webm") {
    return "a video is a .mp4 (H.264) or .webm (VP8) file, not '" + path.filename().string() + "'";
  }
  // The checks every output has (a directory, a missing or unwritable directory).
  if (const std::string why = outputProblem(path); !why.empty()) return why;
  if (findFfmpeg().empty()) {
    return "ffmpeg is not installed (Debian's package ffmpeg; scripts/install-deps.sh installs it)";
  }
  return "";
}

VideoWriter::VideoWriter(std::filesystem::path path, int width, int height, double fps)
    : path_(std::move(path)), width_(width), height_(height) {
  if (const std::string why = problem(path_); !why.empty()) fail(path_, why);
  temporary_ = path_;
  temporary_ += ".tmp." + std::to_string(::getpid());
  const bool mp4 = path_.extension() == ".mp4";
  // yuv420p wants even sizes: an odd window is padded by a pixel.
  std::vector<std::string> args = {findFfmpeg(),
                                   "-hide_banner",
                                   "-loglevel",
                                   "error",
                                   "-y",
                                   "-f",
                                   "rawvideo",
                                   "-pix_fmt",
                                   "rgb24",
                                   "-s",
                                   std::to_string(width) + "x" + std::to_string(height),
                                   "-r",
                                   format(fps),
                                   "-i",
                                   "-",
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-pix_fmt",
                                   "yuv420p"};
  const std::vector<std::string> codec =
      mp4 ? std::vector<std::string>{"-c:v", "libx264",   "-preset",    "veryfast", "-crf",
                                     "20",   "-movflags", "+faststart", "-f",       "mp4"}
          : std::vector<std::string>{"-c:v", "libvpx", "-deadline", "realtime", "-cpu-used",
                                     "8",    "-b:v",   "4M",        "-f",       "webm"};
  args.insert(args.end(), codec.begin(), codec.end());
  args.push_back(temporary_.string());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) fail(path_, std::string("pipe: ") + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  const int spawned = ::posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (spawned != 0) {
    ::close(fds[1]);
    pid_ = -1;
    fail(path_, std::string("cannot start ffmpeg: ") + std::strerror(spawned));
  }
  pipe_ = fds[1];
  // A write to an ffmpeg that stopped reading fails with EPIPE instead of ending the viewer.
  ::signal(SIGPIPE, SIG_IGN);
}

VideoWriter::~VideoWriter() {
  stop();
}

void VideoWriter::add(const Image& image) {
  if (pipe_ < 0) fail(path_, "the video is finished");
  if (image.width != width_ || image.height != height_) {
    fail(path_, "a frame of " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                    " in a video of " + std::to_string(width_) + "x" + std::to_string(height_));
  }
  const std::uint8_t* data = image.rgb.data();
  std::size_t left = image.rgb.size();
  while (left > 0) {
    const ssize_t n = ::write(pipe_, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      stop();
      fail(path_, err == EPIPE ? std::string("ffmpeg stopped reading frames")
                               : std::string("write: ") + std::strerror(err));
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  ++frames_;
}

void VideoWriter::finish() {
  if (pipe_ < 0) fail(path_, "the video is finished");
  ::close(pipe_);
  pipe_ = -1;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  std::error_code ec;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::filesystem::remove(temporary_, ec);
    fail(path_, WIFEXITED(status)
                    ? "ffmpeg failed (exit " + std::to_string(WEXITSTATUS(status)) + ")"
                    : "ffmpeg ended by signal " + std::to_string(WTERMSIG(status)));
  }
  std::filesystem::rename(temporary_, path_, ec);
  if (ec) {
    std::filesystem::remove(temporary_, ec);
    fail(path_, "rename: " + ec.message());
  }
}

void VideoWriter::stop() {
  if (pipe_ >= 0) {
    ::close(pipe_);
    pipe_ = -1;
  }
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
  }
}

}  // namespace jello::viewer
