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

// Least-squares slope of log(error) against log(dt).
double slope(const std::vector<std::pair<double, double>>& points);

}  // namespace jello::experiments
