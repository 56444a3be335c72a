#include "experiments/studies/study_integrators.h"

#include <algorithm>
#include <cctype>
#include <optional>

#include "src/base/closed_set.h"

namespace jello::experiments {

std::vector<IntegratorKind> studyOrder() {
  std::vector<IntegratorKind> kinds(allIntegrators().begin(), allIntegrators().end());
  std::stable_partition(kinds.begin(), kinds.end(),
                        [](IntegratorKind kind) { return !isAdaptive(kind); });
  return kinds;
}

std::vector<IntegratorKind> fixedStepIntegrators() {
  std::vector<IntegratorKind> kinds = studyOrder();
  std::erase_if(kinds, isAdaptive);
  return kinds;
}

std::vector<IntegratorKind> dampingRepresentatives() {
  std::vector<IntegratorKind> kinds;
  for (LinearModel model :
       {LinearModel::BackwardEuler, LinearModel::Bdf2, LinearModel::Trapezoidal}) {
    for (IntegratorKind kind : allIntegrators()) {
      if (linearModel(kind) == model) {
        kinds.push_back(kind);
        break;
      }
    }
  }
  return kinds;
}

namespace {

constexpr IntegratorFamily kFamilies[] = {IntegratorFamily::Explicit, IntegratorFamily::Newton,
                                          IntegratorFamily::Linearized, IntegratorFamily::Cvode,
                                          IntegratorFamily::Projective};

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::optional<IntegratorFamily> parseFamily(const std::string& name) {
  for (IntegratorFamily family : kFamilies) {
    if (closed_set::equalsIgnoreCase(familyName(family), name)) return family;
  }
  return std::nullopt;
}

}  // namespace

std::variant<std::vector<IntegratorKind>, std::string> namedIntegrators(
    const std::vector<std::string>& names, const std::vector<IntegratorKind>& all) {
  std::vector<IntegratorKind> kinds;
  const auto add = [&kinds](IntegratorKind kind) {
    if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) kinds.push_back(kind);
  };
  for (const std::string& name : names) {
    if (const auto kind = parseIntegratorName(name)) {
      add(*kind);
    } else if (const auto family = parseFamily(name)) {
      for (IntegratorKind k : integratorsOf({*family})) add(k);
    } else {
      return name;
    }
  }
  return kinds.empty() ? all : kinds;
}

std::string namedIntegratorsHelp() {
  std::string families;
  for (IntegratorFamily family : kFamilies) {
    families += (families.empty() ? "" : ", ") + lower(familyName(family));
  }
  return integratorNameList() + ", or a family: " + families;
}

std::vector<IntegratorKind> quickAtlasIntegrators() {
  return {IntegratorKind::Symplectic, IntegratorKind::RK4, IntegratorKind::Implicit,
          IntegratorKind::Midpoint, IntegratorKind::Projective};
}

std::vector<IntegratorKind> quickDriftIntegrators() {
  return {IntegratorKind::Symplectic, IntegratorKind::RK4, IntegratorKind::Implicit,
          IntegratorKind::Midpoint};
}

std::vector<IntegratorKind> scalingImplicitIntegrators() {
  return {IntegratorKind::Implicit, IntegratorKind::Cvode};
}

}  // namespace jello::experiments
