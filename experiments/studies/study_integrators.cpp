#include "experiments/studies/study_integrators.h"

#include <algorithm>

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
