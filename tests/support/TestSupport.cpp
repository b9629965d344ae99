#include "support/TestSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/Error.h"

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

LoadedScan decode(std::string_view bytes, std::string_view fileName) {
    return decodeScan(asBytes(bytes), detectFormat(asBytes(bytes), fileName));
}

void expectPosition(const PointCloud& cloud, std::size_t i, double x, double y, double z) {
    const glm::dvec3 p = cloud.fileCoordinates(i);
    EXPECT_NEAR(p.x, x, 2e-6) << "point " << i;
    EXPECT_NEAR(p.y, y, 2e-6) << "point " << i;
    EXPECT_NEAR(p.z, z, 2e-6) << "point " << i;
}

std::string decodeError(std::string_view bytes, std::string_view fileName) {
    try {
        decode(bytes, fileName);
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "decoding " << fileName << " did not throw subscan::Error";
    return {};
}

std::string fileBytes(const std::filesystem::path& file) {
    std::ifstream stream(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(stream), {}};
}

std::size_t lineCount(std::string_view text) {
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
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
    const TempDir capture;
    const std::string outPath = (capture / "stdout").string();
    const std::string errPath = (capture / "stderr").string();

    std::vector<std::string> argv{SUBSCAN_EXECUTABLE};
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
    // GL errors fail the command in the Release builds tests run, unless a test says otherwise.
    std::vector<std::string> variables = environment;
    if (std::none_of(environment.begin(), environment.end(), [](const std::string& added) {
            return added.starts_with("SUBSCAN_GL_DEBUG=");
        })) {
        variables.emplace_back("SUBSCAN_GL_DEBUG=1");
    }
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
        throw std::runtime_error(std::string("cannot start ") + SUBSCAN_EXECUTABLE);
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

}  // namespace subscan::test
