// Frames and screenshots as JPEG files (stb_image_write), written atomically: a full disk or a
// missing directory leaves no partial image and any previous file intact.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace jello::viewer {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // width*height*3, top row first
};

// Flips rows: GL reads the bottom row first.
Image imageFromBottomUp(int width, int height, std::vector<std::uint8_t> rgbBottomUp);

// quality 1..100. Throws std::runtime_error naming the path on failure.
void writeJpeg(const std::filesystem::path& path, const Image& image, int quality = 92);

// Reads a JPEG back (for tests and checks); throws std::runtime_error on failure.
Image readImage(const std::filesystem::path& path);

// The file a recording writes frame `index` to (from 0): "000.jpg", "001.jpg", ...
std::string recordedFrameName(int index);

}  // namespace jello::viewer
