#pragma once

#include <cstddef>
#include <filesystem>
#include <span>

namespace subscan {

/// A whole file mapped read-only into memory (MAP_PRIVATE, so readers can never modify it).
/// Move-only; unmaps on destruction. Empty files give an empty span and no mapping.
///
/// A file that another program shortens while it is mapped would make reads past its new end
/// raise SIGBUS. Instead, such pages read as zeros and shrank() turns true: the caller then
/// reports the truncation rather than what the zeros decoded to.
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
    /// Whether a read found the file shorter than when it was mapped.
    bool shrank() const;

  private:
    const std::byte* data_ = nullptr;
    std::size_t size_ = 0;
    int guardSlot_ = -1;  // this mapping's entry in the SIGBUS guard's table, or -1
};

}  // namespace subscan
