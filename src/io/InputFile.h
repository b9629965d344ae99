#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace subscan {

/// A file opened read-only and read in pieces at any offset (pread), for readers that must not
/// hold the whole file: memory holds only what the caller asks for. Reads from several threads
/// at once are safe. Move-only; closes on destruction. Errors are subscan::Error sentences
/// without the path (the caller names the file).
class InputFile {
  public:
    explicit InputFile(const std::filesystem::path& path);
    ~InputFile();
    InputFile(InputFile&& other) noexcept;
    InputFile& operator=(InputFile&& other) noexcept;
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    /// The size when the file was opened.
    std::uint64_t size() const { return size_; }
    /// Fills `out` with the bytes at `offset`; throws when the file ends before (it was
    /// truncated after opening, or the caller's offsets come from a corrupt header).
    void read(std::uint64_t offset, std::span<std::byte> out) const;
    std::vector<std::byte> read(std::uint64_t offset, std::size_t size) const;
    /// Fills as much of `out` as the file holds from `offset`; returns how many bytes that is.
    std::size_t readSome(std::uint64_t offset, std::span<std::byte> out) const;

  private:
    int fd_ = -1;
    std::uint64_t size_ = 0;
};

}  // namespace subscan
