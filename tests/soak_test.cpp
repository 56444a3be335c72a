// Long runs (ctest label `soak`): every reference world, 100,000 rk4 steps at its own dt (5 to
// 50 simulated seconds; 200,000 until the CI budget asked for the time) and
// 600 implicit steps at dt = 0.01 (6 s, converged Newton: several factorizations a step),
// with no divergence, no growth of memory, and total energy
// (kinetic + spring + contact) minus the work done by the field never more than 1% above its
// start. rotate.w starts at rest (2e-7 J) and is driven by its field, so the 1% is taken of
// the largest total energy the run reaches, not of the start alone.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "solvers/simulation.h"
#include "tests/test_support.h"

namespace jello {
namespace {

long residentKilobytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

struct Soak {
  std::string world;
  IntegratorKind kind;
  long steps;
  double dt;  // 0: the world's own
  friend void PrintTo(const Soak& s, std::ostream* os) { *os << s.world; }
};

class SoakTest : public ::testing::TestWithParam<Soak> {};

TEST_P(SoakTest, RunsWithoutDivergenceMemoryGrowthOrEnergyGain) {
  const Soak& soak = GetParam();
  Simulation sim(test::loadWorld(soak.world), soak.kind,
                 soak.dt > 0 ? std::optional<double>(soak.dt) : std::nullopt);
  const double e0 = sim.model().energy(sim.state()).total();
  double work = 0.0, worstExcess = 0.0, largest = e0;
  long rssAfterWarmUp = 0;
  Eigen::VectorXd previous = sim.state().x;
  for (long i = 0; i < soak.steps; ++i) {
    const StepResult r = sim.step();
    ASSERT_TRUE(r.ok) << r.message;
    work += sim.model().fieldWork(previous.data(), sim.state().x.data());
    previous = sim.state().x;
    const double e = sim.model().energy(sim.state()).total();
    largest = std::max(largest, e);
    worstExcess = std::max(worstExcess, e - work - e0);
    if (i == soak.steps / 10) rssAfterWarmUp = residentKilobytes();
  }
  EXPECT_LE(worstExcess, 0.01 * largest)
      << "energy minus field work rose " << worstExcess << " J above its start " << e0 << " J";
  const long growth = residentKilobytes() - rssAfterWarmUp;
  EXPECT_LT(growth, 2048) << "resident memory grew by " << growth << " kB";
}

std::vector<Soak> soaks() {
  std::vector<Soak> all;
  for (const char* w : {"jello.w", "moveLeft.w", "rotate.w", "skewedCorner.w", "gravity.w",
                        "createWorld-default.w"}) {
    all.push_back({w, IntegratorKind::RK4, 100000, 0.0});
    all.push_back({w, IntegratorKind::Implicit, 600, 0.01});
  }
  return all;
}

std::string soakName(const ::testing::TestParamInfo<Soak>& param_info) {
  std::string name = param_info.param.world.substr(0, param_info.param.world.find('.'));
  name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
  return name + "_" + std::string(integratorName(param_info.param.kind));
}

INSTANTIATE_TEST_SUITE_P(ReferenceWorlds, SoakTest, ::testing::ValuesIn(soaks()), soakName);

}  // namespace
}  // namespace jello
