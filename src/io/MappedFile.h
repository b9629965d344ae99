#pragma once

#include <cstddef>
#include <filesystem>
#include <span>

namespace subscan {

/// A whole file mapped read-only into memory (MAP_PRIVATE, so readers can never modify it).
/// Move-only; unmaps on destruction. Empty files give an empty span and no mapping.
class MappedFile {
  public:
    /// Throws subscan::Error (without the path; the caller names the file) when the file cannot be
    /// opened or mapped.
    explicit MappedFile(const std::filesystem::path& path);
    ~MappedFile();
    MappedFile(MappedFile&& other) noexcept;
    MappedFile& operator=(MappedFile&& other) noexcept;
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;

    std::span<const std::byte> bytes() const { return {data_, size_}; }

  private:
    const std::byte* data_ = nullptr;
    std::size_t size_ = 0;
};

}  // namespace subscan
