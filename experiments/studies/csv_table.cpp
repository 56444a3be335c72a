#include "experiments/studies/csv_table.h"

#include <cstdio>
#include <sstream>

#include "src/atomic_file.h"

namespace jello::experiments {

CsvTable::CsvTable(std::vector<std::string> columns) : columns_(std::move(columns)) {}

void CsvTable::add(std::vector<Cell> row) {
  std::lock_guard lock(mutex_);
  rows_.push_back(std::move(row));
}

std::string CsvTable::text() const {
  std::lock_guard lock(mutex_);
  std::ostringstream os;
  for (std::size_t i = 0; i < columns_.size(); ++i) os << (i ? "," : "") << columns_[i];
  os << '\n';
  for (const auto& row : rows_) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i) os << ',';
      if (const double* d = std::get_if<double>(&row[i])) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.17g", *d);
        os << buf;
      } else if (const long* l = std::get_if<long>(&row[i])) {
        os << *l;
      } else {
        os << std::get<std::string>(row[i]);
      }
    }
    os << '\n';
  }
  return os.str();
}

void CsvTable::write(const std::filesystem::path& path) const {
  writeFileAtomically(path, text());
}

}  // namespace jello::experiments
