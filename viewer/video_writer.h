// Recorded frames as a video (`jello --record-video FILE.mp4`): Debian's ffmpeg, the program,
// reads raw RGB frames through a pipe and encodes them (.mp4: H.264, .webm: VP8) at
// kRecordedFramesPerSecond. It writes a temporary file beside the target, renamed over it only
// when ffmpeg has finished cleanly: a failed or interrupted recording leaves no partial video
// and any previous file intact.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>

#include "viewer/image_writer.h"

namespace jello::viewer {

class VideoWriter {
 public:
  // Why `path` cannot be a video (not .mp4 or .webm, ffmpeg not installed, a directory that
  // does not exist), or empty: checked before anything is drawn.
  static std::string problem(const std::filesystem::path& path);

  // Starts ffmpeg for frames of width x height at `fps`. Throws std::runtime_error naming the
  // path.
  VideoWriter(std::filesystem::path path, int width, int height, double fps);
  ~VideoWriter();  // unfinished: stops ffmpeg and removes the temporary file
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // One frame of the size given; throws when ffmpeg has stopped reading.
  void add(const Image& image);
  // Closes the pipe, waits for ffmpeg, checks how it ended and renames the video into place.
  // Throws std::runtime_error naming the path and ffmpeg's exit status.
  void finish();
  int frames() const { return frames_; }

 private:
  void stop();

  std::filesystem::path path_, temporary_;
  int width_ = 0, height_ = 0, frames_ = 0;
  int pipe_ = -1;
  pid_t pid_ = -1;
};

}  // namespace jello::viewer
