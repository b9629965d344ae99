#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/PointCloud.h"
#include "io/ScanLoader.h"

namespace subscan::test {

/// A fresh directory under the system temp dir, removed with everything in it on destruction.
class TempDir {
  public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(std::string_view name) const { return path_ / name; }
    /// Writes `bytes` to a file in this directory and returns its path.
    std::filesystem::path write(std::string_view name, std::string_view bytes) const;

  private:
    std::filesystem::path path_;
};

std::span<const std::byte> asBytes(std::string_view text);

/// Decodes an in-memory file as loadScan would after reading it (format by content, then name).
LoadedScan decode(std::string_view bytes, std::string_view fileName = "scan");

/// The message of the subscan::Error that decode() throws; fails the test if none is thrown.
std::string decodeError(std::string_view bytes, std::string_view fileName = "scan");

struct CommandResult {
    int exitCode = -1;  // -1: killed by a signal (a crash)
    std::string out;
    std::string err;
};

/// Runs the subscan executable built with this test, with `arguments`; never through a shell.
/// `environment` entries ("NAME=value") are added to (or override) the test's environment.
CommandResult runSubscan(const std::vector<std::string>& arguments,
                         const std::vector<std::string>& environment = {});

/// The shared real-scan folder ($SUBSCAN_TEST_DATA, else ../shared/data beside the checkout),
/// or nullopt when it is absent (tests then GTEST_SKIP with a visible message).
std::optional<std::filesystem::path> testDataDirectory();

/// Expects point i of `cloud` at (x, y, z) in file coordinates. Positions are floats relative to
/// the cloud's centre; the test clouds span less than 10 units, where float steps are ~1e-6.
void expectPosition(const PointCloud& cloud, std::size_t i, double x, double y, double z);

/// Appends the bytes of `value` in little- or big-endian order.
template <class T>
void appendBytes(std::string& out, T value, bool bigEndian = false) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if (bigEndian) {
        std::reverse(bytes, bytes + sizeof(T));
    }
    out.append(bytes, sizeof(T));
}

}  // namespace subscan::test

/// Skips the current test with a visible message when the real-scan folder is absent.
#define SUBSCAN_REQUIRE_TEST_DATA(dirVariable)                                               \
    const auto dirVariable##Optional = ::subscan::test::testDataDirectory();                 \
    if (!dirVariable##Optional) {                                                            \
        GTEST_SKIP() << "real scans not found: set SUBSCAN_TEST_DATA or put ../shared/data " \
                        "beside the checkout";                                               \
    }                                                                                        \
    const std::filesystem::path dirVariable = *dirVariable##Optional
