#include "solvers/integrator.h"

namespace jello {

std::optional<double> findStatistic(const std::vector<Statistic>& statistics,
                                    std::string_view name) {
  for (const Statistic& s : statistics) {
    if (s.name == name) return s.value;
  }
  return std::nullopt;
}

}  // namespace jello
