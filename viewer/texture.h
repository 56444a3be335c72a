// The jello's optional texture (key t, --texture): an image file (JPEG or PNG, read by stb_image)
// or, by default, a built-in pattern made here, mapped once onto each face of the cube
// (SurfaceMesh::uv). GL-free: the renderer uploads the image.
#pragma once

#include <filesystem>

#include "viewer/image_writer.h"

namespace jello::viewer {

// The built-in pattern, `size` pixels square: a bold checker of `cells` x `cells` squares of
// jello red and deep red, outlined in darker red (the default: one square per lattice cell of
// the 8^3 cube's faces), so deformation reads at a glance.
Image builtinTexture(int size = 256, int cells = 7);

// An image file as a texture, resampled (nearest) to a power-of-two square of at most 1024
// pixels for OpenGL 1. Throws std::runtime_error naming the file when it cannot be read.
Image loadTexture(const std::filesystem::path& path);

}  // namespace jello::viewer
