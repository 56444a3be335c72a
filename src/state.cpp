#include "src/state.h"

#include "src/base/assertions.h"

namespace jello {

State initialState(const World& world) {
  const int n = world.numPoints();
  JELLO_ASSERT(static_cast<int>(world.positions.size()) == n,
               "a world holds one position per point");
  State s;
  s.x.resize(3 * n);
  s.v.resize(3 * n);
  for (int p = 0; p < n; ++p) {
    State::set(s.x, p, world.positions[p]);
    State::set(s.v, p, world.velocities[p]);
  }
  return s;
}

void storeState(const State& state, World& world) {
  const int n = state.numPoints();
  world.positions.resize(n);
  world.velocities.resize(n);
  for (int p = 0; p < n; ++p) {
    world.positions[p] = state.position(p);
    world.velocities[p] = state.velocity(p);
  }
}

}  // namespace jello
