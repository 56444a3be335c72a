// What every closed set's table (integrators, linear solvers, preconditioners, contact models)
// answers from its rows: a name parsed in any case, a kind's row, the names listed. A table is
// a constexpr array of rows with members `kind` (an enum class numbering the rows from 0) and
// `name`, filled from the set's X-macro, so adding a row is one change (house style).
#pragma once

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace jello::closed_set {

// The row of a table that needs no more than a name and a line saying what it is.
template <class Kind>
struct Row {
  Kind kind;
  std::string_view name;
  std::string_view summary;
};

// Every kind of a table, in its order.
template <class RowType, std::size_t N>
constexpr auto kinds(const RowType (&rows)[N]) {
  std::array<decltype(rows[0].kind), N> out{};
  for (std::size_t i = 0; i < N; ++i) out[i] = rows[i].kind;
  return out;
}

inline bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char p, char q) {
           return std::tolower(static_cast<unsigned char>(p)) ==
                  std::tolower(static_cast<unsigned char>(q));
         });
}

// The row whose name is `name` (any case), or nothing.
template <class Rows>
auto parse(const Rows& rows, std::string_view name) -> std::optional<decltype(rows[0].kind)> {
  for (const auto& row : rows) {
    if (equalsIgnoreCase(name, row.name)) return row.kind;
  }
  return std::nullopt;
}

// The row of `kind`: the enumerators count the table's rows from 0.
template <class Rows, class Kind>
const auto& row(const Rows& rows, Kind kind) {
  return rows[static_cast<std::size_t>(kind)];
}

// "a, b, c" (or with another separator): for help texts and error messages.
template <class Rows>
std::string names(const Rows& rows, std::string_view separator = ", ") {
  std::string list;
  for (const auto& row : rows) {
    if (!list.empty()) list += separator;
    list += row.name;
  }
  return list;
}

// Every row's name, in the table's order (for a command line's list of choices).
template <class Rows>
std::vector<std::string> nameList(const Rows& rows) {
  std::vector<std::string> list;
  for (const auto& row : rows) list.emplace_back(row.name);
  return list;
}

// "A, B or C", each item written by format(item): a table's rows in a sentence.
template <class Items, class Format>
std::string sentence(const Items& items, Format format) {
  std::string text;
  const std::size_t count = std::size(items);
  std::size_t i = 0;
  for (const auto& item : items) {
    text += i == 0 ? "" : i + 1 == count ? " or " : ", ";
    text += format(item);
    ++i;
  }
  return text;
}

}  // namespace jello::closed_set
