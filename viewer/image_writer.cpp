#include "viewer/image_writer.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "src/base/atomic_file.h"

// stb is header-only: its implementation lives in this one file.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_JPEG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace jello::viewer {

Image imageFromBottomUp(int width, int height, std::vector<std::uint8_t> rgbBottomUp) {
  Image image{width, height, std::move(rgbBottomUp)};
  const std::size_t row = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height / 2; ++y) {
    std::uint8_t* top = image.rgb.data() + row * static_cast<std::size_t>(y);
    std::uint8_t* bottom = image.rgb.data() + row * static_cast<std::size_t>(height - 1 - y);
    std::swap_ranges(top, top + row, bottom);
  }
  return image;
}

void writeJpeg(const std::filesystem::path& path, const Image& image, int quality) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3) {
    throw std::runtime_error(path.string() + ": no image to write");
  }
  std::string bytes;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
  };
  if (stbi_write_jpg_to_func(append, &bytes, image.width, image.height, 3, image.rgb.data(),
                             quality) == 0) {
    throw std::runtime_error(path.string() + ": JPEG encoding failed");
  }
  writeFileAtomically(path, bytes);
}

std::string recordedFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof name, "%03d.jpg", index);
  return name;
}

Image readImage(const std::filesystem::path& path) {
  // Read twice (its size, then its pixels): a FIFO would block forever or lose its start.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(
        path.string() + ": cannot read image: " +
        (std::filesystem::exists(path, error) ? "not a regular file" : "no such file"));
  }
  int width = 0, height = 0, channels = 0;
  // Refused before decoding: a huge image would allocate gigabytes.
  if (stbi_info(path.c_str(), &width, &height, &channels) && (width > 16384 || height > 16384)) {
    throw std::runtime_error(path.string() + ": image of " + std::to_string(width) + "x" +
                             std::to_string(height) + " pixels is too large (16384 at most)");
  }
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
      stbi_load(path.c_str(), &width, &height, &channels, 3), stbi_image_free);
  if (!pixels) {
    throw std::runtime_error(path.string() + ": cannot read image: " + stbi_failure_reason());
  }
  const std::size_t size = static_cast<std::size_t>(width) * height * 3;
  Image image{width, height, std::vector<std::uint8_t>(size)};
  std::memcpy(image.rgb.data(), pixels.get(), size);
  return image;
}

}  // namespace jello::viewer
