#include "support/TestSupport.h"

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

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

namespace {

std::string readWhole(const std::filesystem::path& file) {
    std::ifstream stream(file, std::ios::binary);
    std::ostringstream contents;
    contents << stream.rdbuf();
    return contents.str();
}

}  // namespace

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
    std::vector<std::string> variables = environment;
    for (char** entry = environ; *entry != nullptr; ++entry) {
        const std::string_view existing(*entry);
        const std::string_view name = existing.substr(0, existing.find('='));
        const bool overridden = std::any_of(
            environment.begin(), environment.end(),
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
    result.out = readWhole(outPath);
    result.err = readWhole(errPath);
    return result;
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
