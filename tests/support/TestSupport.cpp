#include "support/TestSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"

extern char** environ;

namespace subscan::test {

TempDir::TempDir() {
    std::random_device random;
    for (int attempt = 0; attempt < 100; ++attempt) {
        const auto candidate =
            std::filesystem::temp_directory_path() / ("subscan-test-" + std::to_string(random()));
        if (std::filesystem::create_directory(candidate)) {
            path_ = candidate;
            return;
        }
    }
    throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path TempDir::write(std::string_view name, std::string_view bytes) const {
    const std::filesystem::path file = path_ / name;
    std::ofstream stream(file, std::ios::binary);
    stream.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!stream) {
        throw std::runtime_error("cannot write " + file.string());
    }
    return file;
}

std::span<const std::byte> asBytes(std::string_view text) {
    return {reinterpret_cast<const std::byte*>(text.data()), text.size()};
}

std::size_t lasVlrPayloadOffset(std::string_view file, std::string_view userId) {
    const auto field = [&](std::size_t offset) {
        return loadLittleEndian<std::uint16_t>(file.data() + offset);
    };
    std::size_t position = field(las::header_field::kHeaderSize);
    const auto count = loadLittleEndian<std::uint32_t>(file.data() + las::header_field::kVlrCount);
    for (std::uint32_t i = 0; i < count && position + las::kVlrHeaderSize <= file.size(); ++i) {
        if (file.substr(position + las::kVlrUserIdOffset, userId.size()) == userId) {
            return position + las::kVlrHeaderSize;
        }
        position += las::kVlrHeaderSize + field(position + las::kVlrLengthOffset);
    }
    return 0;
}

LoadedScan decode(std::string_view bytes, std::string_view fileName) {
    return decodeScan(asBytes(bytes), detectFormat(asBytes(bytes), fileName));
}

void expectPosition(const PointCloud& cloud, std::size_t i, double x, double y, double z) {
    const glm::dvec3 p = cloud.fileCoordinates(i);
    EXPECT_NEAR(p.x, x, 2e-6) << "point " << i;
    EXPECT_NEAR(p.y, y, 2e-6) << "point " << i;
    EXPECT_NEAR(p.z, z, 2e-6) << "point " << i;
}

std::string errorMessage(const std::function<void()>& call) {
    try {
        call();
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "the call did not throw subscan::Error";
    return {};
}

std::string decodeError(std::string_view bytes, std::string_view fileName) {
    SCOPED_TRACE("decoding " + std::string(fileName));
    return errorMessage([&] { decode(bytes, fileName); });
}

std::string fileBytes(const std::filesystem::path& file) {
    std::ifstream stream(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(stream), {}};
}

std::size_t lineCount(std::string_view text) {
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

std::vector<std::string> folderEntries(const std::filesystem::path& folder) {
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

void expectUnwritablePathIsAnErrorNamingIt(
    const std::function<void(const std::filesystem::path&)>& write, std::string_view fileName) {
    const TempDir dir;
    const std::filesystem::path path = dir / "missing" / fileName;
    try {
        write(path);
        ADD_FAILURE() << "no error for a directory that does not exist";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr(path.string()));
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "something was written";
}

CommandResult runSubscan(const std::vector<std::string>& arguments,
                         const std::vector<std::string>& environment) {
    // GL errors fail the command in the Release builds tests run, unless a test says otherwise.
    std::vector<std::string> variables = environment;
    if (std::none_of(environment.begin(), environment.end(), [](const std::string& added) {
            return added.starts_with("SUBSCAN_GL_DEBUG=");
        })) {
        variables.emplace_back("SUBSCAN_GL_DEBUG=1");
    }
    return runProgram(SUBSCAN_EXECUTABLE, arguments, variables);
}

CommandResult renderSmallSphere(const std::string& out, const std::vector<std::string>& options) {
    std::vector<std::string> arguments{"render", "synthetic:sphere", "-o", out, "--width",
                                       "32",     "--height",         "24"};
    arguments.insert(arguments.end(), options.begin(), options.end());
    return runSubscan(arguments);
}

std::string subscanExecutable() {
    return SUBSCAN_EXECUTABLE;
}

CommandResult runProgram(const std::string& executable, const std::vector<std::string>& arguments,
                         const std::vector<std::string>& environment) {
    const TempDir capture;
    const std::string outPath = (capture / "stdout").string();
    const std::string errPath = (capture / "stderr").string();

    std::vector<std::string> argv{executable};
    argv.insert(argv.end(), arguments.begin(), arguments.end());
    std::vector<char*> argvPointers;
    for (std::string& argument : argv) {
        argvPointers.push_back(argument.data());
    }
    argvPointers.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, outPath.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, errPath.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> variables = environment;
    const std::size_t given = variables.size();
    for (char** entry = environ; *entry != nullptr; ++entry) {
        const std::string_view existing(*entry);
        const std::string_view name = existing.substr(0, existing.find('='));
        const bool overridden = std::any_of(
            variables.begin(), variables.begin() + static_cast<std::ptrdiff_t>(given),
            [&](const std::string& added) { return added.starts_with(std::string(name) + "="); });
        if (!overridden) {
            variables.emplace_back(existing);
        }
    }
    std::vector<char*> environmentPointers;
    for (std::string& variable : variables) {
        environmentPointers.push_back(variable.data());
    }
    environmentPointers.push_back(nullptr);

    pid_t pid = 0;
    const int spawnError = posix_spawn(&pid, argvPointers[0], &actions, nullptr,
                                       argvPointers.data(), environmentPointers.data());
    posix_spawn_file_actions_destroy(&actions);
    if (spawnError != 0) {
        throw std::runtime_error("cannot start " + executable);
    }
    int status = 0;
    waitpid(pid, &status, 0);

    CommandResult result;
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = fileBytes(outPath);
    result.err = fileBytes(errPath);
    return result;
}

void expectPositionsNear(const PointCloud& actual, const PointCloud& expected, double tolerance) {
    ASSERT_EQ(actual.size(), expected.size());
    int failures = 0;
    for (std::size_t i = 0; i < expected.size() && failures < 10; ++i) {
        const glm::dvec3 a = actual.fileCoordinates(i);
        const glm::dvec3 e = expected.fileCoordinates(i);
        for (int axis = 0; axis < 3; ++axis) {
            if (!(std::abs(a[axis] - e[axis]) <= tolerance)) {
                ADD_FAILURE() << "point " << i << " axis " << axis << ": " << a[axis] << " vs "
                              << e[axis] << " (tolerance " << tolerance << ")";
                ++failures;  // a few are enough to see what is wrong with 110,000 points
            }
        }
    }
}

PointCloud cloudOf(const std::vector<glm::dvec3>& positions) {
    PointCloudBuilder builder({}, positions.size());
    for (const glm::dvec3& position : positions) {
        PointRecord record;
        record.position = position;
        builder.add(record);
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

PointCloud utmCloudWithEveryAttribute() {
    const glm::dvec3 corner(512345.25, 5432109.5, 97.0);
    const glm::dvec3 offsets[] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {2.5, 5, 10}, {10, 10, 7.5}};
    const float intensities[] = {0.0f, 1.25f, 2.5f, 70000.0f, -3.0f};
    PointCloudBuilder builder({.color = true, .normal = true, .intensity = true}, 5);
    for (int i = 0; i < 5; ++i) {
        PointRecord record;
        record.position = corner + offsets[i];
        record.color = {static_cast<std::uint8_t>(60 * i), 200, static_cast<std::uint8_t>(255 - i),
                        255};
        record.normal = glm::normalize(glm::vec3(i, 1, -i));
        record.intensity = intensities[i];
        builder.add(record);
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

std::optional<std::filesystem::path> testDataDirectory() {
    std::filesystem::path directory;
    if (const char* fromEnvironment = std::getenv("SUBSCAN_TEST_DATA");
        fromEnvironment != nullptr && *fromEnvironment != '\0') {
        directory = fromEnvironment;
    } else {
        directory = std::filesystem::path(SUBSCAN_SOURCE_DIR) / ".." / "shared" / "data";
    }
    if (!std::filesystem::is_directory(directory)) {
        return std::nullopt;
    }
    return directory;
}

namespace {

/// Reads little-endian values and NUL-terminated strings from a file's bytes, in order.
class ExrCursor {
  public:
    explicit ExrCursor(std::string bytes) : bytes_(std::move(bytes)) {}

    template <class T>
    T value() {
        T result{};
        need(sizeof(T));
        std::memcpy(&result, bytes_.data() + position_, sizeof(T));
        position_ += sizeof(T);
        return result;
    }
    std::string text() {
        const std::size_t end = bytes_.find('\0', position_);
        if (end == std::string::npos) {
            throw std::runtime_error("an unterminated name");
        }
        std::string result = bytes_.substr(position_, end - position_);
        position_ = end + 1;
        return result;
    }
    std::string bytes(std::size_t count) {
        need(count);
        std::string result = bytes_.substr(position_, count);
        position_ += count;
        return result;
    }
    void seek(std::uint64_t position) {
        if (position > bytes_.size()) {
            throw std::runtime_error("an offset beyond the end of the file");
        }
        position_ = static_cast<std::size_t>(position);
    }

  private:
    void need(std::size_t count) const {
        if (bytes_.size() - position_ < count) {
            throw std::runtime_error("the file ends early");
        }
    }

    std::string bytes_;
    std::size_t position_ = 0;
};

}  // namespace

ExrFile readExr(const std::filesystem::path& path) {
    ExrCursor cursor(fileBytes(path));
    ExrFile file;
    file.magic = cursor.value<std::uint32_t>();
    file.version = cursor.value<std::uint32_t>();
    for (std::string name = cursor.text(); !name.empty(); name = cursor.text()) {
        ExrAttribute attribute{name, cursor.text(), {}};
        attribute.value = cursor.bytes(static_cast<std::size_t>(cursor.value<std::int32_t>()));
        file.attributes.push_back(std::move(attribute));
    }
    const auto find = [&](std::string_view name) -> const std::string& {
        for (const ExrAttribute& attribute : file.attributes) {
            if (attribute.name == name) {
                return attribute.value;
            }
        }
        throw std::runtime_error("no " + std::string(name) + " attribute");
    };
    if (find("compression") != std::string(1, '\0')) {
        throw std::runtime_error("compressed");
    }
    ExrCursor window(find("dataWindow"));
    const auto xMin = window.value<std::int32_t>();
    const auto yMin = window.value<std::int32_t>();
    const auto xMax = window.value<std::int32_t>();
    const auto yMax = window.value<std::int32_t>();
    file.image = {xMax - xMin + 1, yMax - yMin + 1, 3, {}};
    const auto width = static_cast<std::size_t>(file.image.width);
    file.image.values.resize(width * static_cast<std::size_t>(file.image.height) * 3);

    std::vector<std::size_t> channelIndices;  // R, G, B -> 0, 1, 2, in the list's order
    ExrCursor channels(find("channels"));
    for (std::string name = channels.text(); !name.empty(); name = channels.text()) {
        const auto type = channels.value<std::int32_t>();
        channels.bytes(4);  // pLinear and reserved
        const auto xSampling = channels.value<std::int32_t>();
        const auto ySampling = channels.value<std::int32_t>();
        const std::size_t index = std::string_view("RGB").find(name);
        if (type != 2 || xSampling != 1 || ySampling != 1 || name.size() != 1 ||
            index == std::string_view::npos) {
            throw std::runtime_error("channel " + name + " is not a FLOAT R, G or B");
        }
        channelIndices.push_back(index);
    }

    for (int block = 0; block < file.image.height; ++block) {
        file.offsets.push_back(cursor.value<std::uint64_t>());
    }
    for (const std::uint64_t offset : file.offsets) {
        cursor.seek(offset);
        const auto y = cursor.value<std::int32_t>();
        const auto size = cursor.value<std::int32_t>();
        file.blockRows.push_back(y);
        if (y < yMin || y > yMax ||
            static_cast<std::size_t>(size) != width * channelIndices.size() * sizeof(float)) {
            throw std::runtime_error("a block of row " + std::to_string(y) + " and " +
                                     std::to_string(size) + " bytes");
        }
        float* row = file.image.values.data() + static_cast<std::size_t>(y - yMin) * width * 3;
        for (const std::size_t channel : channelIndices) {
            for (std::size_t x = 0; x < width; ++x) {
                row[3 * x + channel] = cursor.value<float>();
            }
        }
    }
    return file;
}

}  // namespace subscan::test
