// What every experiment program shares: long-format CSV written atomically, a JSON sidecar
// describing the run (arguments, commit, compiler, BLAS, machine), and a pool that runs
// independent grid points on all cores with a progress line.
#pragma once

#include <filesystem>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

namespace jello::experiments {

// Rows of one table; columns carry their unit in the name (dt_s, k_N_per_m, ...).
class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns);
  // Values in column order; numbers are written with %.17g, strings as they are (no commas).
  using Cell = std::variant<double, long, std::string>;
  void add(std::vector<Cell> row);
  std::size_t rows() const { return rows_.size(); }
  std::string text() const;
  void write(const std::filesystem::path& path) const;  // atomically

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<Cell>> rows_;
  mutable std::mutex mutex_;
};

// The run's context for the sidecar: the command line, the source commit (and whether the
// tree had changes), the compiler, the BLAS this process loaded, the machine and the date.
nlohmann::json runContext(int argc, char** argv);
void writeSidecar(const std::filesystem::path& path, const nlohmann::json& sidecar);

// Writes `table` to DIR/NAME.csv, each of `extra` to DIR/NAME_<suffix>.csv and the sidecar
// to DIR/NAME.json, creating DIR. On failure prints "<program>: error: ..." and returns false.
bool writeResults(const std::string& program, const std::filesystem::path& dir,
                  const std::string& name, const CsvTable& table, const nlohmann::json& sidecar,
                  const std::vector<std::pair<std::string, const CsvTable*>>& extra = {});

// Which BLAS this process loaded (CHOLMOD's supernodal factorization depends on it).
std::string loadedBlas();

// Runs task(i) for i in [0, count) on `jobs` threads, in order of i, with a progress line on
// standard error labelled `label` (silent when !progress). Exceptions propagate after all
// threads stop.
void parallelFor(int count, int jobs, const std::string& label, bool progress,
                 const std::function<void(int)>& task);

}  // namespace jello::experiments
