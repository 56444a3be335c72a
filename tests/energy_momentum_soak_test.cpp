// energy-momentum over 1,000 steps (ctest label `soak`: about ten minutes in release, beyond CI's
// budget; tests/energy_momentum_test.cpp runs the same check over 20 steps): the undamped
// spinning stretched cube at k = 1e4, 1e5 and 1e6, dt = 0.01, keeps its total energy to 1e-9
// and its angular momentum to 1e-11 at every step, every step converged.
#include "tests/energy_momentum_support.h"

namespace jello {
namespace {

TEST(EnergyMomentumSoak, KeepsTheEnergyAndAngularMomentumOverAThousandSteps) {
  for (double k : {1e4, 1e5, 1e6}) test::expectConserved(k, 1000);
}

}  // namespace
}  // namespace jello
