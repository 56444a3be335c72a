// What the tests of the experiment programs share: running a program, reading its CSV and
// checking its sidecar.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace jello::experiments {

using Table = std::vector<std::map<std::string, std::string>>;

// A CSV with a header row, one map per row (column -> cell).
Table readCsv(const std::filesystem::path& path);

// A program's exit code, run without its progress line.
int run(const std::string& command);

double number(const std::map<std::string, std::string>& row, const std::string& column);

// The sidecar names `program` and holds the run's record (command line, commit, ...).
void expectSidecar(const std::filesystem::path& path, const char* program);

// The quick atlas's RK4 references (N = 8, k = 1e3 and 1e5, falling and free scenes), kept in
// tests/data/atlas-quick-references/ (a quarter of a minute each to compute), copied into `dir`:
// the `--atlas-references` a test's quick atlas reads. The test
// ScalingCli.TheKeptQuickReferencesAreTodaysScenes recomputes those at k = 1e3 against them.
std::filesystem::path quickReferences(const std::filesystem::path& dir);

// Least-squares slope of log(error) against log(dt).
double slope(const std::vector<std::pair<double, double>>& points);

}  // namespace jello::experiments
