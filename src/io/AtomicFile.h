#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace subscan {

/// Writes a file so that readers never see a partial one: the content goes to a temporary file
/// in the same directory, which is flushed and renamed over `path` only when complete. On any
/// failure the temporary file is removed, `path` is untouched, and subscan::Error names it.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& writeContent);

/// Convenience for content already in memory.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace subscan
