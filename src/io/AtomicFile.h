#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>

namespace subscan {

/// Writes a file so that readers never see a partial one: the content goes to a temporary file
/// in the same directory, which is flushed and renamed over `path` only when complete. On any
/// failure the temporary file is removed, `path` is untouched, and subscan::Error names it.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& writeContent);

/// Convenience for content already in memory.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

/// The name of the file writeFileAtomically was writing where `name` is one of its temporary
/// files' (".NAME.0123abcd.tmp"), which a process killed while writing leaves; else nullopt.
std::optional<std::string> atomicWriteTargetOf(std::string_view name);

}  // namespace subscan
