#pragma once

#include <filesystem>
#include <string_view>

namespace subscan {

/// A folder of temporary files, made inside `parent` with a unique name starting with `prefix`,
/// removed with everything in it when this goes away (on success, failure and Ctrl-C alike).
class TemporaryFolder {
  public:
    /// Throws subscan::Error naming `parent` when the folder cannot be made there.
    TemporaryFolder(const std::filesystem::path& parent, std::string_view prefix);
    ~TemporaryFolder();
    TemporaryFolder(const TemporaryFolder&) = delete;
    TemporaryFolder& operator=(const TemporaryFolder&) = delete;

    const std::filesystem::path& path() const { return path_; }

  private:
    std::filesystem::path path_;
};

}  // namespace subscan
