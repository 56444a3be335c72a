// The atlas's trace (issue 39, item 5; jello-scaling --atlas-trace): the visible motion over time
// of the reference and of an integrator at its largest step, so that a missed cell can be seen.
// The reference's rows start at rest shape and fall freely until the impact; an integrator's
// rows' largest corner distance is the error the atlas's search gives that step.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "experiments/studies/atlas.h"
#include "tests/test_support.h"

namespace jello::experiments {
namespace {

// A table's rows (its header left out), each a list of cells as written.
std::vector<std::vector<std::string>> cellsOf(const CsvTable& table) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream text(table.text());
  std::string line;
  std::getline(text, line);  // the header
  while (std::getline(text, line)) {
    std::vector<std::string> cells;
    std::istringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}
double number(const std::string& cell) {
  return std::stod(cell);
}

TEST(AtlasTrace, TheReferenceFallsFreelyAndARunsLargestDistanceIsItsAtlasError) {
  const double k = 1e3;
  const int n = 4;
  const World w = atlasScene(k, n);
  AtlasSetup setup;
  setup.halvings = 1;  // the atlas's search at the largest step alone
  const AtlasReference ref = atlasReference(w, k, AtlasScene::Falling, setup);
  CsvTable trace = atlasTraceTable();
  atlasTrace(w, k, n, std::nullopt, ref, setup, trace);
  const std::size_t samples = ref.samples.size();
  const auto rows = cellsOf(trace);
  ASSERT_EQ(rows.size(), samples);
  const double g = 9.81;
  for (std::size_t i = 0; i < samples; ++i) {
    const auto& row = rows[i];
    const double t = number(row[5]);
    EXPECT_NEAR(t, 0.02 * double(i), 1e-12);
    EXPECT_EQ(row[2], "reference");
    EXPECT_EQ(number(row[9]), 0.0);
    // Falling freely from rest height 0 until the impact at about 0.55 s (the floor at z = -2,
    // the bottom face at -0.5 at the start).
    if (t <= 0.5) {
      EXPECT_NEAR(number(row[6]), -0.5 * g * t * t, 1e-6) << t;
    }
  }
  EXPECT_NEAR(number(rows[0][7]), 1.0, 1e-12);  // the rest shape's height

  CsvTable cells = atlasTable();
  atlasPoint(w, k, n, IntegratorKind::Implicit, ref, setup, cells);
  CsvTable run = atlasTraceTable();
  atlasTrace(w, k, n, IntegratorKind::Implicit, ref, setup, run);
  const auto runRows = cellsOf(run);
  ASSERT_EQ(runRows.size(), samples - 1);  // t = 0.02 .. 1 s
  double largest = 0.0;
  for (const auto& row : runRows) {
    EXPECT_EQ(number(row[3]), setup.interval);
    largest = std::max(largest, number(row[9]));
  }
  const auto cellRows = cellsOf(cells);
  ASSERT_EQ(cellRows.size(), 1u);
  EXPECT_GT(largest, 0.0);
  EXPECT_NEAR(largest, number(cellRows[0][8]), 1e-12 * largest);
}

}  // namespace
}  // namespace jello::experiments
