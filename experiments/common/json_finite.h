// JSON has no infinity or NaN (nlohmann writes them as null): what the programs write says why
// a value is null.
#pragma once

#include <nlohmann/json.hpp>

namespace jello {

// Replaces every non-finite number in `doc` (an object) by null and records under
// doc["null_because"], keyed by its path ("energy_end.contact"), "not finite: inf". Reasons a
// caller already put there (a null set on purpose) are kept.
void explainNonFinite(nlohmann::json& doc);

}  // namespace jello
