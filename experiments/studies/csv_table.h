// Long-format CSV tables of the experiment programs: one row per measurement, units in the
// column names (dt_s, k_N_per_m, ...), written atomically.
#pragma once

#include <filesystem>
#include <mutex>
#include <string>
#include <variant>
#include <vector>

namespace jello::experiments {

// Rows of one table; rows may be added from several threads. Their order does not depend on
// threads or MPI ranks: rows added by a task of parallelFor (parallel_for.h) are ordered by
// the task's index, then in the order that task added them; rows added outside any task come
// first, in the order added.
class CsvTable {
 public:
  explicit CsvTable(std::vector<std::string> columns);
  // Values in column order; numbers are written with %.17g, strings as they are (no commas).
  using Cell = std::variant<double, long, std::string>;
  void add(const std::vector<Cell>& row);
  std::size_t rows() const;
  std::string text() const;
  void write(const std::filesystem::path& path) const;  // atomically

  // The rows with their order keys, as text for another process; merge() adds such rows.
  std::string serialize() const;
  void merge(const std::string& serialized);
  void clear();

 private:
  struct Row {
    long task, sequence;
    std::string line;  // formatted, without its newline
  };
  std::vector<std::string> columns_;
  std::vector<Row> rows_;
  mutable std::mutex mutex_;
};

// The task the calling thread is running for parallelFor (-1 outside any task); set by
// parallelFor through TaskScope.
long currentTask();
class TaskScope {
 public:
  explicit TaskScope(long task);
  ~TaskScope();
  TaskScope(const TaskScope&) = delete;
  TaskScope& operator=(const TaskScope&) = delete;

 private:
  long previous_;
};

}  // namespace jello::experiments
