#include "experiments/studies/csv_table.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "src/base/atomic_file.h"

namespace jello::experiments {

namespace {

thread_local long tlsTask = -1;

std::string format(const std::vector<CsvTable::Cell>& row) {
  std::string line;
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (i) line += ',';
    if (const double* d = std::get_if<double>(&row[i])) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g", *d);
      line += buf;
    } else if (const long* l = std::get_if<long>(&row[i])) {
      line += std::to_string(*l);
    } else {
      line += std::get<std::string>(row[i]);
    }
  }
  return line;
}

}  // namespace

long currentTask() {
  return tlsTask;
}
TaskScope::TaskScope(long task) : previous_(tlsTask) {
  tlsTask = task;
}
TaskScope::~TaskScope() {
  tlsTask = previous_;
}

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void CsvTable::add(const std::vector<Cell>& row) {
  std::string line = format(row);
  const long task = currentTask();
  std::lock_guard lock(mutex_);
  const long sequence = long(
      std::count_if(rows_.begin(), rows_.end(), [task](const Row& r) { return r.task == task; }));
  rows_.push_back({task, sequence, std::move(line)});
}

std::size_t CsvTable::rows() const {
  std::lock_guard lock(mutex_);
  return rows_.size();
}

std::string CsvTable::text() const {
  std::vector<Row> sorted;
  {
    std::lock_guard lock(mutex_);
    sorted = rows_;
  }
  std::stable_sort(sorted.begin(), sorted.end(), [](const Row& a, const Row& b) {
    return a.task != b.task ? a.task < b.task : a.sequence < b.sequence;
  });
  std::string out;
  for (std::size_t i = 0; i < columns_.size(); ++i) out += (i ? "," : "") + columns_[i];
  out += '\n';
  for (const Row& r : sorted) out += r.line + '\n';
  return out;
}

void CsvTable::write(const std::filesystem::path& path) const {
  writeFileAtomically(path, text());
}

std::string CsvTable::serialize() const {
  std::lock_guard lock(mutex_);
  std::string out;
  for (const Row& r : rows_) {
    out += std::to_string(r.task) + ' ' + std::to_string(r.sequence) + ' ' + r.line + '\n';
  }
  return out;
}

void CsvTable::merge(const std::string& serialized) {
  std::istringstream in(serialized);
  std::vector<Row> rows;
  for (std::string line; std::getline(in, line);) {
    Row r{};
    std::istringstream fields(line);
    if (!(fields >> r.task >> r.sequence) || fields.get() != ' ') {
      throw std::runtime_error("a gathered CSV row is malformed: '" + line + "'");
    }
    std::getline(fields, r.line);
    rows.push_back(std::move(r));
  }
  std::lock_guard lock(mutex_);
  rows_.insert(rows_.end(), rows.begin(), rows.end());
}

void CsvTable::clear() {
  std::lock_guard lock(mutex_);
  rows_.clear();
}

}  // namespace jello::experiments
