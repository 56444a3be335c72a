// Long-format CSV tables of the experiment programs: one row per measurement, units in the
// column names (dt_s, k_N_per_m, ...), written atomically.
#pragma once

#include <filesystem>
#include <mutex>
#include <string>
#include <variant>
#include <vector>

namespace jello::experiments {

// Rows of one table; rows may be added from several threads.
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

}  // namespace jello::experiments
