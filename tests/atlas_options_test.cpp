// Choosing an atlas's runs (jello-scaling --atlas-integrators, --atlas-steps-tried,
// --atlas-first-step): which integrators, how many steps each, and from which step the implicit
// ones start, so that one question (how an implicit method's error falls with its step on the
// friction scene) can be asked of a few methods down to small steps without the whole atlas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "experiments/studies/study_integrators.h"
#include "tests/experiments_support.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

std::vector<IntegratorKind> named(const std::vector<std::string>& names) {
  auto kinds = namedIntegrators(names, {IntegratorKind::RK4});
  EXPECT_TRUE(std::holds_alternative<std::vector<IntegratorKind>>(kinds));
  return std::holds_alternative<std::vector<IntegratorKind>>(kinds)
             ? std::get<std::vector<IntegratorKind>>(kinds)
             : std::vector<IntegratorKind>{};
}

TEST(NamedIntegrators, NamesAndFamiliesInTheirOrderNoneTwiceTheDefaultWhenNone) {
  EXPECT_EQ(named({}), std::vector<IntegratorKind>{IntegratorKind::RK4});
  EXPECT_EQ(named({"newton"}), integratorsOf({IntegratorFamily::Newton}));
  EXPECT_EQ(named({"Explicit"}), integratorsOf({IntegratorFamily::Explicit}));
  // A name and the family holding it: once, where first named.
  const auto kinds = named({"bdf2", "newton", "implicit-linear"});
  ASSERT_FALSE(kinds.empty());
  EXPECT_EQ(kinds.front(), IntegratorKind::Bdf2);
  EXPECT_EQ(kinds.back(), IntegratorKind::ImplicitLinear);
  EXPECT_EQ(kinds.size(), integratorsOf({IntegratorFamily::Newton}).size() + 1);
  for (IntegratorKind kind : kinds) {
    EXPECT_EQ(std::count(kinds.begin(), kinds.end(), kind), 1) << integratorName(kind);
  }
  const auto unknown = namedIntegrators({"implicit", "verlet"}, {});
  ASSERT_TRUE(std::holds_alternative<std::string>(unknown));
  EXPECT_EQ(std::get<std::string>(unknown), "verlet");
  // The help names every integrator and every family.
  const std::string help = namedIntegratorsHelp();
  for (IntegratorKind kind : allIntegrators()) {
    EXPECT_NE(help.find(integratorName(kind)), std::string::npos) << integratorName(kind);
  }
  EXPECT_NE(help.find("linearized"), std::string::npos);
}

TEST(ScalingCli, AtlasIntegratorsStepsTriedAndFirstStepChooseTheRuns) {
  test::TempDir dir;
  const std::string base = std::string(JELLO_SCALING) +
                           " --quick --no-grid --atlas-n 4 --atlas-k 1e2 --jobs 1 --out-dir " +
                           dir.path().string();
  EXPECT_EQ(run(base + " --atlas-integrators implicit,verlet"), 2);
  EXPECT_EQ(run(base + " --atlas-steps-tried 0"), 2);
  // Not the 0.02 s sample interval over a whole number: the samples would fall between steps.
  EXPECT_EQ(run(base + " --atlas-first-step 0.015"), 2);
  EXPECT_EQ(run(base + " --atlas-first-step 0.03"), 2);

  // Never within the tolerance: every step tried is run.
  ASSERT_EQ(run(base + " --atlas-integrators linearized,implicit,implicit --atlas-steps-tried 3 " +
                "--atlas-first-step 0.005 --atlas-tolerance 1e-9"),
            0);
  const Table cells = readCsv(dir.path() / "scaling_atlas.csv");
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[0].at("integrator"), "implicit-linear");
  EXPECT_EQ(cells[1].at("integrator"), "implicit");
  const Table tries = readCsv(dir.path() / "scaling_tries.csv");
  ASSERT_EQ(tries.size(), 6u);
  for (std::size_t i = 0; i < tries.size(); ++i) {
    EXPECT_EQ(tries[i].at("integrator"), cells[i / 3].at("integrator"));
    EXPECT_EQ(number(tries[i], "dt_s"), 0.005 / std::pow(2.0, double(i % 3))) << i;
    EXPECT_EQ(tries[i].at("finished"), "1") << i;
  }
  // The trace runs each at that first step.
  ASSERT_EQ(run(base + " --atlas-integrators implicit --atlas-first-step 0.005 --atlas-trace"), 0);
  int traced = 0;
  for (const auto& row : readCsv(dir.path() / "scaling_trace.csv")) {
    if (row.at("integrator") != "implicit") continue;
    EXPECT_EQ(number(row, "dt_s"), 0.005);
    ++traced;
  }
  EXPECT_EQ(traced, 50);  // t = 0.02 .. 1 s
}

}  // namespace
}  // namespace jello::experiments
