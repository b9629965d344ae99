#include "io/InputFile.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

InputFile::InputFile(const std::filesystem::path& path)
    : fd_(::open(path.c_str(), O_RDONLY | O_CLOEXEC)) {
    if (fd_ < 0) {
        throw Error(fmt::format("cannot open the file: {}", std::strerror(errno)));
    }
    struct stat status {};
    const bool known = ::fstat(fd_, &status) == 0;
    const int error = errno;
    if (!known || !S_ISREG(status.st_mode)) {
        ::close(fd_);
        fd_ = -1;
        if (!known) {
            throw Error(fmt::format("cannot read the file size: {}", std::strerror(error)));
        }
        throw Error(S_ISDIR(status.st_mode) ? "it is a directory, not a scan file"
                                            : "it is not a regular file");
    }
    size_ = static_cast<std::uint64_t>(status.st_size);
    // Readers go front to back through most of a file: the kernel may read ahead generously.
    ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
}

InputFile::~InputFile() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

InputFile::InputFile(InputFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), size_(std::exchange(other.size_, 0)) {}

InputFile& InputFile::operator=(InputFile&& other) noexcept {
    if (this != &other) {
        if (fd_ >= 0) {
            ::close(fd_);
        }
        fd_ = std::exchange(other.fd_, -1);
        size_ = std::exchange(other.size_, 0);
    }
    return *this;
}

std::size_t InputFile::readSome(std::uint64_t offset, std::span<std::byte> out) const {
    std::size_t done = 0;
    while (done < out.size()) {
        const ssize_t got =
            ::pread(fd_, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
        if (got < 0) {
            if (errno == EINTR) {
                continue;
            }
            throw Error(fmt::format("cannot read {} bytes at byte {}: {}", out.size(), offset,
                                    std::strerror(errno)));
        }
        if (got == 0) {
            break;  // the end of the file
        }
        done += static_cast<std::size_t>(got);
    }
    return done;
}

void InputFile::read(std::uint64_t offset, std::span<std::byte> out) const {
    if (readSome(offset, out) != out.size()) {
        throw Error(
            fmt::format("the file ends before byte {} (it had {} bytes when opened; truncated, "
                        "or is its header wrong?)",
                        offset + out.size(), size_));
    }
}

std::vector<std::byte> InputFile::read(std::uint64_t offset, std::size_t size) const {
    std::vector<std::byte> bytes(size);
    read(offset, bytes);
    return bytes;
}

}  // namespace subscan
