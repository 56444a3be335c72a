#include "experiments/common/json_finite.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace jello {
namespace {

void explain(nlohmann::json& value, const std::string& path, nlohmann::json& because) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", value.get<double>());
    because[path] = std::string("not finite: ") + text;
    value = nullptr;
  } else if (value.is_object()) {
    for (auto& [key, item] : value.items()) {
      explain(item, path.empty() ? key : path + "." + key, because);
    }
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      explain(value[i], path + "[" + std::to_string(i) + "]", because);
    }
  }
}

}  // namespace

void explainNonFinite(nlohmann::json& doc) {
  nlohmann::json because = doc.value("null_because", nlohmann::json::object());
  explain(doc, "", because);
  if (!because.empty()) doc["null_because"] = because;
}

}  // namespace jello
