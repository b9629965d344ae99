#include "io/MappedFile.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

/// Closes a file descriptor on scope exit; the mapping outlives it.
struct FileDescriptor {
    int fd;
    ~FileDescriptor() {
        if (fd >= 0) {
            ::close(fd);
        }
    }
};

}  // namespace

MappedFile::MappedFile(const std::filesystem::path& path) {
    FileDescriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
    if (file.fd < 0) {
        throw Error(fmt::format("cannot open the file: {}", std::strerror(errno)));
    }
    struct stat info {};
    if (::fstat(file.fd, &info) != 0) {
        throw Error(fmt::format("cannot read the file size: {}", std::strerror(errno)));
    }
    if (S_ISDIR(info.st_mode)) {
        throw Error("it is a directory, not a scan file");
    }
    if (!S_ISREG(info.st_mode)) {
        throw Error("it is not a regular file");
    }
    size_ = static_cast<std::size_t>(info.st_size);
    if (size_ == 0) {
        return;
    }
    void* mapping = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, file.fd, 0);
    if (mapping == MAP_FAILED) {
        throw Error(fmt::format("cannot map the file into memory: {}", std::strerror(errno)));
    }
    // Readers go front to back; tell the kernel so it reads ahead generously.
    ::madvise(mapping, size_, MADV_SEQUENTIAL);
    ::madvise(mapping, size_, MADV_WILLNEED);
    data_ = static_cast<const std::byte*>(mapping);
}

MappedFile::~MappedFile() {
    if (data_ != nullptr) {
        ::munmap(const_cast<std::byte*>(data_), size_);
    }
}

MappedFile::MappedFile(MappedFile&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
    if (this != &other) {
        this->~MappedFile();
        data_ = std::exchange(other.data_, nullptr);
        size_ = std::exchange(other.size_, 0);
    }
    return *this;
}

}  // namespace subscan
