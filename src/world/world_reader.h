// Reads a world file (worlds/README.md): the original course format, then an optional
// extension block after the velocities. Every error names file, line and token; nothing
// half-read is ever returned.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "src/world/world.h"

namespace jello {

// Hostile sizes are refused before anything is allocated for them.
struct ReaderLimits {
  int maxFieldResolution = 128;            // nodes per axis: 128^3 nodes = 50 MB
  int maxCubeResolution = 64;              // points per axis: 64^3 points
  std::uintmax_t maxFileBytes = 1u << 28;  // 256 MiB
  // An integrator name not in our table is accepted (the world keeps RK4 and records the name
  // in World::unknownIntegrator) when the caller overrides the integrator anyway: files by
  // other authors of the course name integrators they added (`Midpoint`, `IPC`).
  bool acceptUnknownIntegrator = false;
};

// A token of a file as a message shows it: at most `limit` bytes (a 50 MB "number" is not
// repeated, its size said instead), control and non-ASCII bytes as \xNN, so no terminal escape
// code passes through (keepUtf8: non-ASCII bytes kept, for file names). Every message that quotes
// a file's content goes through it.
inline constexpr std::size_t kShownTokenBytes = 40;
std::string displayToken(std::string_view token, std::size_t limit = kShownTokenBytes,
                         bool keepUtf8 = false, std::size_t bytes = 0);

class WorldFileError : public std::runtime_error {
 public:
  // `tokenBytes`: the token's full length when `token` holds only its start (0: its own size).
  WorldFileError(std::string file, int line, std::string token, const std::string& message,
                 std::size_t tokenBytes = 0);

  const std::string& file() const { return file_; }
  int line() const { return line_; }  // 1-based; 0 when the file could not be opened
  const std::string& token() const { return token_; }

 private:
  std::string file_;
  int line_;
  std::string token_;
};

// The reader's checks of a cube's start, which the Python module's setters share: a point
// farther than kStartBound from the origin (or not finite), two points at one place (the springs
// between them would have no direction; `other` is the first of them), a velocity whose kinetic
// energy is not finite. `point` is the one to blame.
struct PointProblem {
  std::size_t point = 0;
  std::size_t other = 0;
  std::string message;
};
std::optional<PointProblem> positionsProblem(const std::vector<Vec3>& positions);
std::optional<PointProblem> velocitiesProblem(const std::vector<Vec3>& velocities, double mass);

// Throws WorldFileError.
World readWorld(const std::filesystem::path& path, const ReaderLimits& limits = {});

// Parses a world from text; `name` is what error messages call the file.
World parseWorld(std::string_view text, const std::string& name, const ReaderLimits& limits = {});

}  // namespace jello
