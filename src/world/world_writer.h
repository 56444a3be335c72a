// Writes a world file. Exact format: every double with 17 significant digits, so a read gives
// back the same bits. Legacy format: six decimals, as the original course's createWorld printed
// (its default output is byte-identical to reference-worlds/createWorld-default.w).
#pragma once

#include <filesystem>
#include <string>

#include "src/world/world.h"

namespace jello {

enum class NumberFormat { Exact, Legacy };

std::string formatWorld(const World& world, NumberFormat format = NumberFormat::Exact);

// Atomic (temporary file, then rename); throws std::runtime_error naming the path.
void writeWorld(const World& world, const std::filesystem::path& path,
                NumberFormat format = NumberFormat::Exact);

}  // namespace jello
