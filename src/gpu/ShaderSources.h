#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace subscan {

/// Shader sources by path relative to shaders/: the embedded copies, or files from an override
/// directory (for iterating on a shader without rebuilding; $SUBSCAN_SHADER_DIR by default).
/// `#include "path"` lines are resolved recursively (each file once), with #line directives so
/// compiler messages point at the right file and line.
class ShaderSources {
  public:
    /// Uses $SUBSCAN_SHADER_DIR as override directory when it is set.
    ShaderSources();
    /// Throws subscan::Error when `overrideDirectory` is given but is not a directory.
    explicit ShaderSources(std::optional<std::filesystem::path> overrideDirectory);

    /// The complete source of `path`, includes expanded, `defines` inserted after #version.
    /// Throws subscan::Error for a missing file or include cycle.
    std::string load(std::string_view path, std::string_view defines = {}) const;

    /// The raw text of one file (no include expansion).
    std::string raw(std::string_view path) const;

  private:
    std::optional<std::filesystem::path> overrideDirectory_;
};

}  // namespace subscan
