#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/PointCloud.h"
#include "io/Image.h"
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

/// Where the payload of the first VLR with this user id lies in a LAS file, or 0 (none).
std::size_t lasVlrPayloadOffset(std::string_view file, std::string_view userId);

/// The whole file's bytes (empty when it cannot be read).
std::string fileBytes(const std::filesystem::path& file);

/// The number of newline characters in `text`.
std::size_t lineCount(std::string_view text);

/// The names of the entries in `folder`, sorted: "nothing but ... is left".
std::vector<std::string> folderEntries(const std::filesystem::path& folder);

/// Expects `write` to a file in a folder that does not exist to throw subscan::Error naming the
/// path, and to leave nothing behind.
void expectUnwritablePathIsAnErrorNamingIt(
    const std::function<void(const std::filesystem::path&)>& write, std::string_view fileName);

/// Decodes an in-memory file as loadScan would after reading it (format by content, then name).
LoadedScan decode(std::string_view bytes, std::string_view fileName = "scan");

/// The message of the subscan::Error that decode() throws; fails the test if none is thrown.
std::string decodeError(std::string_view bytes, std::string_view fileName = "scan");

/// The message of the subscan::Error that `call` throws; fails the test (and returns "") if
/// none is thrown.
std::string errorMessage(const std::function<void()>& call);

struct CommandResult {
    int exitCode = -1;  // -1: killed by a signal (a crash)
    std::string out;
    std::string err;
};

/// Runs the subscan executable built with this test, with `arguments`; never through a shell.
/// `environment` entries ("NAME=value") are added to (or override) the test's environment.
CommandResult runSubscan(const std::vector<std::string>& arguments,
                         const std::vector<std::string>& environment = {});

/// `subscan render synthetic:sphere -o out --width 32 --height 24` and `options`: a picture
/// small enough for any test of the command's options.
CommandResult renderSmallSphere(const std::string& out, const std::vector<std::string>& options);

/// The subscan executable built with this test (for commands that must run through a shell).
std::string subscanExecutable();

/// Runs `executable` (a path) with `arguments` as runSubscan does, without its GL settings.
CommandResult runProgram(const std::string& executable, const std::vector<std::string>& arguments,
                         const std::vector<std::string>& environment = {});

/// The shared real-scan folder ($SUBSCAN_TEST_DATA, else ../shared/data beside the checkout),
/// or nullopt when it is absent (tests then GTEST_SKIP with a visible message).
std::optional<std::filesystem::path> testDataDirectory();

/// Expects point i of `cloud` at (x, y, z) in file coordinates. Positions are floats relative to
/// the cloud's centre; the test clouds span less than 10 units, where float steps are ~1e-6.
void expectPosition(const PointCloud& cloud, std::size_t i, double x, double y, double z);

/// Expects `actual` to hold as many points as `expected`, each within `tolerance` of its
/// counterpart's file coordinates on every axis (the caller says why that tolerance).
void expectPositionsNear(const PointCloud& actual, const PointCloud& expected, double tolerance);

/// A cloud of these positions (file coordinates) and nothing else, as a reader builds it.
PointCloud cloudOf(const std::vector<glm::dvec3>& positions);

/// The writers' round-trip cloud: 5 points with colour, intensity and normals at UTM-like
/// coordinates, 10 m across from (512345.25, 5432109.5, 97) to (512355.25, 5432119.5, 107).
/// Every coordinate is a multiple of 0.25 m, so the float positions relative to the centre are
/// exact and the file coordinates known to the last bit. Intensities include a fraction, a
/// value above 65535 and a negative one (what LAS must round or clamp).
PointCloud utmCloudWithEveryAttribute();

/// One header attribute of an OpenEXR file: its name, type name and value bytes.
struct ExrAttribute {
    std::string name;
    std::string type;
    std::string value;
};

/// An OpenEXR file read back by the tests' own small reader (OpenEXR file layout: magic, version,
/// header attributes, offset table, uncompressed scanline blocks), independent of the writer.
struct ExrFile {
    std::uint32_t magic = 0;
    std::uint32_t version = 0;
    std::vector<ExrAttribute> attributes;  // in file order
    std::vector<std::uint64_t> offsets;    // one per scanline block
    std::vector<std::int32_t> blockRows;   // the y each block says it holds
    ImageF image;                          // channels R, G, B (3 floats a pixel), rows top first
};

/// Throws std::runtime_error naming what is malformed, or not what it reads: FLOAT channels
/// R, G, B only, no compression, one scanline per block.
ExrFile readExr(const std::filesystem::path& path);

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
