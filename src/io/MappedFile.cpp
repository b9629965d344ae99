#include "io/MappedFile.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <utility>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

// The SIGBUS guard. The kernel reports a read of a mapped page beyond the end of a file that
// shrank after mapping by SIGBUS, and a signal handler can reach no state but static state:
// the live mappings are registered in this fixed table, which the handler searches by the
// faulting address. It maps a page of zeros over the missing one and marks the mapping, so the
// read goes on and the loader reports the truncation afterwards.
constexpr int kGuardSlots = 64;  // mappings open at once; more are mapped unguarded

struct GuardSlot {
    std::atomic<bool> taken{false};
    std::atomic<std::uintptr_t> begin{0};  // published last; 0 while the slot is not in use
    std::atomic<std::uintptr_t> end{0};
    std::atomic<bool> shrank{false};
};

GuardSlot guardSlots[kGuardSlots];
std::uintptr_t guardPageSize = 4096;
struct sigaction previousBusAction {};

void onBusError(int signal, siginfo_t* info, void* context) {
    const auto address = reinterpret_cast<std::uintptr_t>(info->si_addr);
    for (GuardSlot& slot : guardSlots) {
        const std::uintptr_t begin = slot.begin.load(std::memory_order_acquire);
        if (begin != 0 && address >= begin && address < slot.end.load(std::memory_order_acquire)) {
            void* page = reinterpret_cast<void*>(address & ~(guardPageSize - 1));
            if (::mmap(page, guardPageSize, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1,
                       0) != MAP_FAILED) {
                slot.shrank.store(true, std::memory_order_release);
                return;  // the read is retried and finds zeros
            }
        }
    }
    // Not a guarded mapping: whatever handled SIGBUS before (by default, the end).
    if ((previousBusAction.sa_flags & SA_SIGINFO) != 0 &&
        previousBusAction.sa_sigaction != nullptr) {
        previousBusAction.sa_sigaction(signal, info, context);
        return;
    }
    if (previousBusAction.sa_handler != SIG_DFL && previousBusAction.sa_handler != SIG_IGN &&
        previousBusAction.sa_handler != nullptr) {
        previousBusAction.sa_handler(signal);
        return;
    }
    ::signal(SIGBUS, SIG_DFL);  // returning re-runs the read, which now ends the process
}

void installGuard() {
    static std::once_flag installed;
    std::call_once(installed, [] {
        guardPageSize = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
        struct sigaction action {};
        action.sa_sigaction = onBusError;
        action.sa_flags = SA_SIGINFO | SA_NODEFER;
        sigemptyset(&action.sa_mask);
        ::sigaction(SIGBUS, &action, &previousBusAction);
    });
}

/// Registers [data, data + size) with the guard; returns its slot, or -1 when all are taken.
int guard(const std::byte* data, std::size_t size) {
    installGuard();
    const auto begin = reinterpret_cast<std::uintptr_t>(data);
    for (int i = 0; i < kGuardSlots; ++i) {
        GuardSlot& slot = guardSlots[i];
        bool taken = false;
        if (slot.taken.compare_exchange_strong(taken, true, std::memory_order_acq_rel)) {
            slot.shrank.store(false, std::memory_order_relaxed);
            slot.end.store(begin + size, std::memory_order_relaxed);
            slot.begin.store(begin, std::memory_order_release);
            return i;
        }
    }
    return -1;
}

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
    guardSlot_ = guard(data_, size_);
}

MappedFile::~MappedFile() {
    if (guardSlot_ >= 0) {
        guardSlots[guardSlot_].begin.store(0, std::memory_order_release);
        guardSlots[guardSlot_].taken.store(false, std::memory_order_release);
    }
    if (data_ != nullptr) {
        ::munmap(const_cast<std::byte*>(data_), size_);
    }
}

MappedFile::MappedFile(MappedFile&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      guardSlot_(std::exchange(other.guardSlot_, -1)) {}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
    if (this != &other) {
        this->~MappedFile();
        data_ = std::exchange(other.data_, nullptr);
        size_ = std::exchange(other.size_, 0);
        guardSlot_ = std::exchange(other.guardSlot_, -1);
    }
    return *this;
}

bool MappedFile::shrank() const {
    return guardSlot_ >= 0 && guardSlots[guardSlot_].shrank.load(std::memory_order_acquire);
}

}  // namespace subscan
