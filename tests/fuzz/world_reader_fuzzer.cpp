// libFuzzer target for the world reader, extension block included. Built and run by
// scripts/fuzz.sh with clang 14 under AddressSanitizer and UndefinedBehaviorSanitizer.
// Contract: any input either parses into a consistent world or throws WorldFileError; a world
// accepted builds its model (springs, field, plane, sphere, cone and spiral obstacles) and its
// forces, energy and contact test evaluate without undefined behaviour at its start; the start
// check the programs and the Python module make after loading (Model::startProblem, naming the
// setting's line) either passes or names a setting the reader recorded, and the reader's point
// checks, which the Python setters share, pass on what it accepted.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "src/model.h"
#include "src/state.h"
#include "src/world/world_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Small limits keep each input's allocations small; the limits themselves are tested.
  jello::ReaderLimits limits;
  limits.maxFieldResolution = 12;
  limits.maxCubeResolution = 6;
  jello::World w;
  try {
    w = jello::parseWorld(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz",
                          limits);
  } catch (const jello::WorldFileError&) {
    return 0;
  }
  const std::size_t n = static_cast<std::size_t>(w.numPoints());
  const std::size_t r = static_cast<std::size_t>(w.field.resolution);
  if (w.positions.size() != n || w.velocities.size() != n || w.field.forces.size() != r * r * r ||
      !(w.dt > 0.0) || !(w.mass > 0.0) || w.stepsPerFrame < 1) {
    std::abort();  // accepted an inconsistent world
  }
  const jello::Model model(w);
  const jello::State s = jello::initialState(w);
  Eigen::VectorXd f;
  model.forces(s.x, s.v, f);
  (void)model.energy(s.x, s.v);
  (void)model.inContact(s.x.data());
  if (jello::positionsProblem(w.positions) || jello::velocitiesProblem(w.velocities, w.mass)) {
    std::abort();  // the setters' checks refuse what the reader accepted
  }
  if (const std::optional<jello::StartProblem> problem = model.startProblem(s)) {
    const jello::WorldFileError e = jello::startError(*problem, w, "fuzz");
    if (e.line() == 0 && problem->what != "velocities") std::abort();  // a line it cannot name
  }
  return 0;
}
