// The jello's optional texture (key t, --texture): an image file (JPEG or PNG, read by stb_image)
// or, by default, a built-in pattern made here, mapped once onto each face of the cube
// (SurfaceMesh::uv). GL-free: the renderer uploads the image.
#pragma once

#include <filesystem>

#include "viewer/image_writer.h"

namespace jello::viewer {

// The built-in pattern: jello red with lighter bubbles and a darker rim, `size` pixels square.
Image builtinTexture(int size = 256);

// An image file as a texture, resampled (nearest) to a power-of-two square of at most 1024
// pixels for OpenGL 1. Throws std::runtime_error naming the file when it cannot be read.
Image loadTexture(const std::filesystem::path& path);

}  // namespace jello::viewer
