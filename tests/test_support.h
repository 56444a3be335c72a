// Shared helpers for the tests: where the worlds are, and small scenes with known answers.
#pragma once

#include <filesystem>
#include <string>

#include "model.h"
#include "world.h"

namespace jello::test {

std::filesystem::path worldsDir();
World loadWorld(const std::string& name);  // a file of worlds/
std::string readFile(const std::filesystem::path& path);

// A fresh, empty directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Two points joined by one spring along x, point 0 at the origin, no walls, no field.
ModelSpec singleSpring(double stiffness, double damping, double rest, double mass);

// jello.w's cube (skewed corner, moving) with walls, plane and field switched off: a free body.
ModelSpec freeCube(const World& world);

}  // namespace jello::test
