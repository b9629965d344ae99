#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

// How the npm interoperability tests find the packages that install-packages.sh (the ctest
// npm_packages) installed into the build folder, and the node to run them with.
namespace subscan::test {

/// Where install-packages.sh put the packages and the reading scripts, and the node to run them
/// with; or why there are none.
struct NpmPackages {
    std::filesystem::path directory;
    std::string node;
    std::string unavailable;  // empty when ready
};

/// Reads $SUBSCAN_NPM_DIR/status.txt ("ready" and node's path, or "skip" and why).
inline NpmPackages npmPackages() {
    NpmPackages packages;
    const char* directory = std::getenv("SUBSCAN_NPM_DIR");
    if (directory == nullptr || *directory == '\0') {
        packages.unavailable = "SUBSCAN_NPM_DIR is not set (run the tests through ctest)";
        return packages;
    }
    packages.directory = directory;
    std::ifstream status(packages.directory / "status.txt");
    std::string state;
    std::string detail;
    if (!std::getline(status, state) || !std::getline(status, detail)) {
        packages.unavailable =
            "the npm packages were not installed (ctest runs the npm_packages "
            "test first: run the npm label, or this test through ctest)";
    } else if (state != "ready") {
        packages.unavailable = detail;
    } else {
        packages.node = detail;
    }
    return packages;
}

}  // namespace subscan::test
