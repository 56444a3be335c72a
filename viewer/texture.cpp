#include "viewer/texture.h"

#include <algorithm>
#include <cmath>

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

Image builtinTexture(int size, int cells) {
  Image image;
  image.width = image.height = size;
  image.rgb.resize(static_cast<std::size_t>(size) * size * 3);
  cells = std::max(cells, 1);
  // A bold checker of jello red and deep red, with a dark line along each cell's edge: every
  // cell is a patch of the face, so the cube's shear and stretch show as the cells deform.
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double fx = (x + 0.5) / size * cells, fy = (y + 0.5) / size * cells;
      const int cx = std::min(cells - 1, int(fx)), cy = std::min(cells - 1, int(fy));
      const double edge = std::min({fx - cx, fy - cy, 1.0 - (fx - cx), 1.0 - (fy - cy)});
      const bool light = (cx + cy) % 2 == 0;
      double shade = light ? 1.0 : 0.55;
      if (edge < 0.06) shade *= 0.6;
      const std::size_t i = (static_cast<std::size_t>(y) * size + x) * 3;
      image.rgb[i] = static_cast<std::uint8_t>(235.0 * shade);
      image.rgb[i + 1] = static_cast<std::uint8_t>((light ? 55.0 : 25.0) * shade);
      image.rgb[i + 2] = static_cast<std::uint8_t>((light ? 75.0 : 40.0) * shade);
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
