#include "src/world/integrator_table.h"

#include <algorithm>

#include "src/base/closed_set.h"

namespace jello {
namespace {

struct Row {
  IntegratorKind kind;
  std::string_view name;
  std::string_view fileName;
  IntegratorFamily family;
  LinearModel model;
  std::string_view summary;
};

constexpr Row kRows[] = {
#define JELLO_INTEGRATOR_ROW(kind, name, fileName, Class, family, model, summary) \
  {IntegratorKind::kind, name, fileName, IntegratorFamily::family, LinearModel::model, summary},
    JELLO_INTEGRATORS(JELLO_INTEGRATOR_ROW)
#undef JELLO_INTEGRATOR_ROW
};

constexpr auto kKinds = closed_set::kinds(kRows);

const Row& row(IntegratorKind kind) {
  return closed_set::row(kRows, kind);
}

bool inFamilies(IntegratorKind kind, std::initializer_list<IntegratorFamily> families) {
  return std::find(families.begin(), families.end(), row(kind).family) != families.end();
}

}  // namespace

std::optional<IntegratorKind> parseIntegratorName(std::string_view name) {
  // The file spellings differ from the names only in case.
  return closed_set::parse(kRows, name);
}

std::string_view integratorName(IntegratorKind kind) {
  return row(kind).name;
}

std::string_view integratorFileName(IntegratorKind kind) {
  return row(kind).fileName;
}

std::string_view integratorSummary(IntegratorKind kind) {
  return row(kind).summary;
}

IntegratorFamily integratorFamily(IntegratorKind kind) {
  return row(kind).family;
}

LinearModel linearModel(IntegratorKind kind) {
  return row(kind).model;
}

std::string_view familyName(IntegratorFamily family) {
  switch (family) {
    case IntegratorFamily::Explicit:
      return "Explicit";
    case IntegratorFamily::Newton:
      return "Newton";
    case IntegratorFamily::Linearized:
      return "Linearized";
    case IntegratorFamily::Cvode:
      return "Cvode";
    case IntegratorFamily::Projective:
      return "Projective";
  }
  return "?";
}

std::string_view linearModelName(LinearModel model) {
  switch (model) {
    case LinearModel::ForwardEuler:
      return "ForwardEuler";
    case LinearModel::SymplecticEuler:
      return "SymplecticEuler";
    case LinearModel::RungeKutta4:
      return "RungeKutta4";
    case LinearModel::BackwardEuler:
      return "BackwardEuler";
    case LinearModel::Bdf2:
      return "Bdf2";
    case LinearModel::Trapezoidal:
      return "Trapezoidal";
    case LinearModel::Adaptive:
      return "Adaptive";
  }
  return "?";
}

bool isExplicit(IntegratorKind kind) {
  return row(kind).family == IntegratorFamily::Explicit;
}

std::span<const IntegratorKind> allIntegrators() {
  return kKinds;
}

std::vector<IntegratorKind> integratorsOf(std::initializer_list<IntegratorFamily> families) {
  std::vector<IntegratorKind> kinds;
  for (IntegratorKind kind : kKinds) {
    if (inFamilies(kind, families)) kinds.push_back(kind);
  }
  return kinds;
}

std::string integratorNameList() {
  return closed_set::names(kRows);
}

std::string integratorNames(std::initializer_list<IntegratorFamily> families) {
  std::string list;
  for (IntegratorKind kind : integratorsOf(families)) {
    if (!list.empty()) list += ", ";
    list += row(kind).name;
  }
  return list;
}

}  // namespace jello
