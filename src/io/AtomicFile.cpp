#include "io/AtomicFile.h"

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

}  // namespace subscan
