#include "integrator_name.h"

#include <algorithm>
#include <array>
#include <cctype>

namespace jello {
namespace {

struct NameEntry {
  IntegratorKind kind;
  std::string_view name;
  std::string_view fileName;
};

constexpr std::array<NameEntry, 5> kNames{{
    {IntegratorKind::Euler, "euler", "Euler"},
    {IntegratorKind::Symplectic, "symplectic", "symplectic"},
    {IntegratorKind::RK4, "rk4", "RK4"},
    {IntegratorKind::Implicit, "implicit", "implicit"},
    {IntegratorKind::Cvode, "cvode", "cvode"},
}};

constexpr std::array<IntegratorKind, kNames.size()> kKinds{
    IntegratorKind::Euler, IntegratorKind::Symplectic, IntegratorKind::RK4,
    IntegratorKind::Implicit, IntegratorKind::Cvode};

bool equalsIgnoreCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char p, char q) {
           return std::tolower(static_cast<unsigned char>(p)) ==
                  std::tolower(static_cast<unsigned char>(q));
         });
}

const NameEntry& entry(IntegratorKind kind) {
  return *std::find_if(kNames.begin(), kNames.end(),
                       [kind](const NameEntry& e) { return e.kind == kind; });
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
