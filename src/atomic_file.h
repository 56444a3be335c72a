// Files are replaced atomically: the contents go to a temporary file in the same directory,
// which is flushed to disk and renamed over the target. A crash, a full disk or a missing
// directory leaves any previous file intact.
#pragma once

#include <filesystem>
#include <string_view>

namespace jello {

// Throws std::runtime_error naming the path and the system's reason.
void writeFileAtomically(const std::filesystem::path& path, std::string_view contents);

}  // namespace jello
