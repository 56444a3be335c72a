#include "viewer/texture.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace jello::viewer {

namespace {

Image resampled(const Image& image, int size) {
  Image out;
  out.width = out.height = size;
  out.rgb.resize(static_cast<std::size_t>(size) * size * 3);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const int sx = std::min(image.width - 1, x * image.width / size);
      const int sy = std::min(image.height - 1, y * image.height / size);
      for (int c = 0; c < 3; ++c) {
        out.rgb[(static_cast<std::size_t>(y) * size + x) * 3 + c] =
            image.rgb[(static_cast<std::size_t>(sy) * image.width + sx) * 3 + c];
      }
    }
  }
  return out;
}

}  // namespace

Image builtinTexture(int size) {
  Image image;
  image.width = image.height = size;
  image.rgb.resize(static_cast<std::size_t>(size) * size * 3);
  // Bubbles: a fixed scatter of discs, lighter towards their centres.
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  struct Bubble {
    double x, y, r;
  };
  std::vector<Bubble> bubbles;
  for (int i = 0; i < 18; ++i) bubbles.push_back({u(rng), u(rng), 0.03 + 0.06 * u(rng)});
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double fx = (x + 0.5) / size, fy = (y + 0.5) / size;
      // Darker towards the face's rim, so the cube's edges read.
      const double edge = std::min({fx, fy, 1.0 - fx, 1.0 - fy});
      double light = 0.75 + 0.25 * std::min(1.0, edge / 0.12);
      for (const Bubble& b : bubbles) {
        const double d = std::hypot(fx - b.x, fy - b.y) / b.r;
        if (d < 1.0) light += 0.35 * (1.0 - d * d);
      }
      const std::size_t i = (static_cast<std::size_t>(y) * size + x) * 3;
      image.rgb[i] = static_cast<std::uint8_t>(std::min(255.0, 230.0 * light));
      image.rgb[i + 1] = static_cast<std::uint8_t>(std::min(255.0, 60.0 * light));
      image.rgb[i + 2] = static_cast<std::uint8_t>(std::min(255.0, 80.0 * light));
    }
  }
  return image;
}

Image loadTexture(const std::filesystem::path& path) {
  const Image image = readImage(path);
  int size = 1;
  while (size < std::max(image.width, image.height) && size < 1024) size *= 2;
  return resampled(image, std::max(size, 2));
}

}  // namespace jello::viewer
