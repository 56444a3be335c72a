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

// Every run of the search is kept (NAME_tries.csv), so that how the error falls with the step
// is seen, not only the step kept: backward Euler on the falling scene loses the whole bounce
// (about 1 m at the corners) until its step resolves the contact, then converges at first
// order, its error halving with the step; a run within the tolerance ends the search, the last
// row then being the atlas's cell.
TEST(AtlasTries, EveryRunOfTheSearchIsKeptWithItsStepAndError) {
  const double k = 1e3;
  const int n = 4;
  const World w = atlasScene(k, n);
  AtlasSetup setup;
  setup.halvings = 8;      // dt = 0.02 to 0.02 / 128
  setup.tolerance = 1e-9;  // never met: every step is tried
  const AtlasReference ref = atlasReference(w, k, AtlasScene::Falling, setup);
  CsvTable cells = atlasTable(), tries = atlasTriesTable();
  atlasPoint(w, k, n, IntegratorKind::Implicit, ref, setup, cells, &tries);
  const auto cellRows = cellsOf(cells), rows = cellsOf(tries);
  ASSERT_EQ(cellRows.size(), 1u);
  EXPECT_EQ(cellRows[0][10], "not_reached");
  ASSERT_EQ(rows.size(), 8u);
  EXPECT_EQ(number(cellRows[0][9]), 8.0);  // tried
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double dt = number(rows[i][3]);
    EXPECT_EQ(rows[i][2], "implicit");
    EXPECT_EQ(dt, setup.interval / std::pow(2.0, double(i)));
    EXPECT_EQ(number(rows[i][5]), std::lround(setup.time / dt));  // steps
    EXPECT_EQ(rows[i][8], "1");                                   // finished
    if (i == 0) continue;
    // Measured: 1.00, 1.00, 0.99, 0.72, then 0.51, 0.52, 0.58 from dt = 0.000625 s.
    const double ratio = number(rows[i][7]) / number(rows[i - 1][7]);
    EXPECT_LT(ratio, 1.0 + 1e-9) << dt;
    if (dt <= 0.000625) {
      EXPECT_GT(ratio, 0.4) << dt;
      EXPECT_LT(ratio, 0.65) << dt;
    }
  }
  EXPECT_GT(number(rows[0][7]), 0.9);                         // the bounce lost, m
  EXPECT_EQ(number(rows.back()[7]), number(cellRows[0][8]));  // the last run's error

  // Within the tolerance at the sixth step: the search ends there, the cell is its run.
  setup.tolerance = 0.5 * (number(rows[4][7]) + number(rows[5][7]));
  CsvTable kept = atlasTable(), some = atlasTriesTable();
  atlasPoint(w, k, n, IntegratorKind::Implicit, ref, setup, kept, &some);
  const auto keptRows = cellsOf(kept), someRows = cellsOf(some);
  ASSERT_EQ(someRows.size(), 6u);
  EXPECT_EQ(keptRows[0][10], "ok");
  EXPECT_EQ(number(keptRows[0][4]), number(someRows[5][3]));  // dt_s
  EXPECT_EQ(number(keptRows[0][8]), number(someRows[5][7]));  // the error
}

}  // namespace
}  // namespace jello::experiments
