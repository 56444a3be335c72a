#include "src/world/integrator_name.h"

#include <algorithm>
#include <array>
#include <cctype>

namespace jello {
namespace {

struct NameEntry {
  IntegratorKind kind;
  std::string_view name;
  std::string_view fileName;
  std::string_view summary;
};

constexpr NameEntry kNames[] = {
#define JELLO_INTEGRATOR_ENTRY(kind, name, fileName, Class, summary) \
  {IntegratorKind::kind, name, fileName, summary},
    JELLO_INTEGRATORS(JELLO_INTEGRATOR_ENTRY)
#undef JELLO_INTEGRATOR_ENTRY
};

constexpr IntegratorKind kKinds[] = {
#define JELLO_INTEGRATOR_KIND(kind, name, fileName, Class, summary) IntegratorKind::kind,
    JELLO_INTEGRATORS(JELLO_INTEGRATOR_KIND)
#undef JELLO_INTEGRATOR_KIND
};

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char p, char q) {
           return std::tolower(static_cast<unsigned char>(p)) ==
                  std::tolower(static_cast<unsigned char>(q));
         });
}

const NameEntry& entry(IntegratorKind kind) {
  return kNames[static_cast<int>(kind)];  // the enumerators count the table's rows from 0
}

}  // namespace

std::optional<IntegratorKind> parseIntegratorName(std::string_view name) {
  for (const NameEntry& e : kNames) {
    if (equalsIgnoreCase(name, e.name)) return e.kind;
  }
  return std::nullopt;
}

std::string_view integratorName(IntegratorKind kind) {
  return entry(kind).name;
}

std::string_view integratorFileName(IntegratorKind kind) {
  return entry(kind).fileName;
}

std::string_view integratorSummary(IntegratorKind kind) {
  return entry(kind).summary;
}

bool isExplicit(IntegratorKind kind) {
  return kind == IntegratorKind::Euler || kind == IntegratorKind::Symplectic ||
         kind == IntegratorKind::RK4;
}

std::span<const IntegratorKind> allIntegrators() {
  return kKinds;
}

std::string integratorNameList() {
  std::string list;
  for (const NameEntry& e : kNames) {
    if (!list.empty()) list += ", ";
    list += e.name;
  }
  return list;
}

}  // namespace jello
