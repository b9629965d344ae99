#include "io/AtomicFile.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <system_error>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& writeContent) {
    namespace fs = std::filesystem;
    const fs::path directory = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(directory)) {
        throw Error(fmt::format("{}: cannot write the file: the directory {} does not exist",
                                path.string(), directory.string()));
    }
    std::random_device random;
    // atomicWriteTargetOf reads this name back.
    const fs::path temporary =
        directory / fmt::format(".{}.{:08x}.tmp", path.filename().string(), random());
    try {
        {
            std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
            if (!stream) {
                throw Error(fmt::format("{}: cannot write the file: {}", path.string(),
                                        std::strerror(errno)));
            }
            writeContent(stream);
            stream.flush();
            if (!stream) {
                throw Error(fmt::format("{}: writing failed (disk full?)", path.string()));
            }
        }
        std::error_code error;
        fs::rename(temporary, path, error);
        if (error) {
            throw Error(
                fmt::format("{}: cannot replace the file: {}", path.string(), error.message()));
        }
    } catch (...) {
        std::error_code ignored;
        fs::remove(temporary, ignored);
        throw;
    }
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
    writeFileAtomically(path, [&](std::ostream& stream) {
        stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    });
}

std::optional<std::string> atomicWriteTargetOf(std::string_view name) {
    constexpr std::string_view kSuffix = ".tmp";
    constexpr std::size_t kHexDigits = 8;  // random()'s 32 bits, as writeFileAtomically writes them
    constexpr std::size_t kShortest = std::string_view(".N.0123abcd.tmp").size();
    if (name.size() < kShortest || !name.starts_with('.') || !name.ends_with(kSuffix)) {
        return std::nullopt;
    }
    const std::string_view withoutSuffix = name.substr(0, name.size() - kSuffix.size());
    const std::string_view digits = withoutSuffix.substr(withoutSuffix.size() - kHexDigits);
    const std::string_view target = withoutSuffix.substr(1, withoutSuffix.size() - kHexDigits - 2);
    const bool lowercaseHex = std::all_of(digits.begin(), digits.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f');
    });
    if (!lowercaseHex || withoutSuffix[withoutSuffix.size() - kHexDigits - 1] != '.') {
        return std::nullopt;
    }
    return std::string(target);
}

}  // namespace subscan
