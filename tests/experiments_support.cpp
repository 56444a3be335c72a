#include "tests/experiments_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/test_support.h"

namespace jello::experiments {

Table readCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> columns;
  Table rows;
  const auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
    return out;
  };
  if (std::getline(in, line)) columns = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < columns.size() && i < cells.size(); ++i) row[columns[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

int run(const std::string& command) {
  return test::run(command + " --quiet").code;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  return std::stod(row.at(column));
}

void expectSidecar(const std::filesystem::path& path, const char* program) {
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("program"), program);
  for (const char* key : {"command_line", "commit", "compiler", "blas", "machine", "parameters",
                          "date_utc", "wall_time_s"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  // The machine as a run's timings need it: its CPU, its vector level, its speed.
  const std::string level = j.at("machine").at("vector_level");
  EXPECT_EQ(level.rfind("x86-64", 0), 0u) << level;
  EXPECT_GT(j.at("machine").at("force_evaluation_8_s").get<double>(), 0.0);
}

double slope(const std::vector<std::pair<double, double>>& points) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (auto [dt, e] : points) {
    const double x = std::log(dt), y = std::log(e);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double n = double(points.size());
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::filesystem::path quickReferences(const std::filesystem::path& dir) {
  const std::filesystem::path refs = dir / "references";
  std::filesystem::create_directories(refs);
  for (const auto& entry :
       std::filesystem::directory_iterator(JELLO_TEST_DATA_DIR "/atlas-quick-references")) {
    std::filesystem::copy_file(entry.path(), refs / entry.path().filename());
  }
  return refs;
}

}  // namespace jello::experiments
