#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "io/PlyWriter.h"
#include "io/ScanLoader.h"
#include "support/TestMeshes.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

TEST(ScanCommandTest, SyntheticSceneScanPrintsJsonAndWritesThePly) {
    const test::TempDir dir;
    const auto out = dir / "torus.ply";
    const test::CommandResult result =
        runSubscan({"scan", "synthetic:torus", "-o", out.string(), "--views", "4", "--resolution",
                    "40", "--noise", "0.2h", "--normals", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json summary = nlohmann::json::parse(result.out);
    std::vector<std::string> keys;
    for (const auto& [key, value] : summary.items()) {
        keys.push_back(key);
    }
    EXPECT_THAT(keys, ::testing::UnorderedElementsAre("points", "views", "resolution", "noise_m",
                                                      "seconds"));
    EXPECT_EQ(summary["views"], 4);
    EXPECT_EQ(summary["resolution"], 40);
    // 0.2 h with h = 6 r / sqrt(8) / 40, r half the diagonal of the torus's 27 x 7 x 27 cm
    // bounds; the JSON carries every digit.
    const double radius = 0.5 * std::sqrt(2.0 * 0.27 * 0.27 + 0.07 * 0.07);
    EXPECT_NEAR(summary["noise_m"].get<double>(), 0.2 * 6.0 * radius / std::sqrt(8.0) / 40.0,
                1e-15);

    const LoadedScan scan = loadScan(out.string());
    EXPECT_EQ(scan.cloud.size(), summary["points"].get<std::size_t>());
    EXPECT_TRUE(scan.cloud.hasColors());  // auto: a built-in scene has colours
    EXPECT_TRUE(scan.cloud.hasNormals());
}

TEST(ScanCommandTest, MeshScanPrintsOneLine) {
    const test::TempDir dir;
    const auto mesh = dir / "ball.ply";
    writePly(mesh, test::sphereMeshes({0.1}, 8, 16));
    const auto out = dir / "scan.ply";
    const test::CommandResult result =
        runSubscan({"scan", mesh.string(), "-o", out.string(), "--resolution", "32"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_EQ(test::lineCount(result.out), 1u);
    EXPECT_THAT(result.out, HasSubstr("points scanned from " + mesh.string()));
    const LoadedScan scan = loadScan(out.string());
    EXPECT_GT(scan.cloud.size(), 1000u);   // 8 views of 32 x 32, the ball fills ~half of each
    EXPECT_FALSE(scan.cloud.hasColors());  // auto: the mesh has none
    EXPECT_FALSE(scan.cloud.hasNormals());

    const test::CommandResult marble = runSubscan(
        {"scan", mesh.string(), "-o", out.string(), "--resolution", "16", "--color", "marble"});
    ASSERT_EQ(marble.exitCode, 0) << marble.err;
    EXPECT_TRUE(loadScan(out.string()).cloud.hasColors());
}

TEST(ScanCommandTest, RefusesToWriteOverItsInput) {
    const test::TempDir dir;
    const auto mesh = dir / "ball.ply";
    writePly(mesh, test::sphereMeshes({0.1}, 8, 16));
    const auto before = std::filesystem::file_size(mesh);
    // Also through another spelling of the same path.
    for (const std::string& output : {mesh.string(), (dir / "." / "ball.ply").string()}) {
        const test::CommandResult result =
            runSubscan({"scan", mesh.string(), "-o", output, "--resolution", "8"});
        EXPECT_EQ(result.exitCode, 1);
        EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
        EXPECT_THAT(result.err, HasSubstr("refusing to write the scan over its own input"));
        EXPECT_EQ(std::filesystem::file_size(mesh), before);
    }
}

TEST(ScanCommandTest, InputErrorsExitWithOneAndLeaveNoOutput) {
    const test::TempDir dir;
    const auto points = dir.write("points.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                  "property float y\nproperty float z\nend_header\n1 2 3\n");
    const auto out = dir / "out.ply";
    const std::vector<std::vector<std::string>> cases{
        {"scan", points.string(), "-o", out.string()},
        {"scan", (dir / "missing.ply").string(), "-o", out.string()},
        {"scan", "synthetic:teapot", "-o", out.string()},
        {"scan", "synthetic:sphere?points=10", "-o", out.string()},
        {"scan", "synthetic:sphere", "-o", (dir / "no-such-dir" / "out.ply").string(),
         "--resolution", "8"},
    };
    const char* messages[] = {"it has no faces", "cannot open the file", "no built-in scene",
                              "takes a bare scene name", "does not exist"};
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const test::CommandResult result = runSubscan(cases[i]);
        EXPECT_EQ(result.exitCode, 1) << cases[i][1];
        EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
        EXPECT_THAT(result.err, HasSubstr(messages[i]));
        EXPECT_TRUE(result.out.empty());
    }
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              1);  // only the input: no output, no temporary
}

TEST(ScanCommandTest, AStationIsPlacedAsXYZOrAsRendersXCommaYCommaZ) {
    const test::TempDir dir;
    std::vector<std::vector<glm::vec3>> scans;
    for (const std::vector<std::string>& station :
         {std::vector<std::string>{"5", "1.5", "3"}, std::vector<std::string>{"5,1.5,3"}}) {
        const auto out = dir / fmt::format("station{}.ply", scans.size());
        std::vector<std::string> arguments{
            "scan", "synthetic:outdoor", "-o", out.string(), "--mode", "station", "--azimuth-steps",
            "90",   "--elevation-steps", "20", "--station"};
        arguments.insert(arguments.end(), station.begin(), station.end());
        const test::CommandResult result = runSubscan(arguments);
        ASSERT_EQ(result.exitCode, 0) << result.err;
        scans.push_back(loadScan(out.string()).cloud.positions);
    }
    EXPECT_GT(scans[0].size(), 100u);
    EXPECT_EQ(scans[0], scans[1]);
    // Two coordinates, or one that is not a number: usage errors.
    for (const std::string bad : {"5,1.5", "5,x,3"}) {
        const test::CommandResult result =
            runSubscan({"scan", "synthetic:outdoor", "-o", (dir / "bad.ply").string(), "--mode",
                        "station", "--station", bad});
        EXPECT_EQ(result.exitCode, 2) << bad;
        EXPECT_FALSE(std::filesystem::exists(dir / "bad.ply"));
    }
}

TEST(ScanCommandTest, BadOptionsExitWithTwo) {
    const test::TempDir dir;
    const auto out = (dir / "out.ply").string();
    const std::vector<std::vector<std::string>> cases{
        {"scan", "synthetic:sphere"},
        {"scan", "synthetic:sphere", "-o", out, "--views", "0"},
        {"scan", "synthetic:sphere", "-o", out, "--resolution", "many"},
        {"scan", "synthetic:sphere", "-o", out, "--noise", "-1"},
        {"scan", "synthetic:sphere", "-o", out, "--noise", "0.1q"},
        {"scan", "synthetic:sphere", "-o", out, "--color", "purple"},
        {"scan", "synthetic:sphere", "-o", out, "--seed", "-3"},
        // Written as PLY whatever its name, which other tools then refused.
        {"scan", "synthetic:sphere", "-o", (dir / "out.las").string()},
    };
    for (const auto& arguments : cases) {
        const test::CommandResult result = runSubscan(arguments);
        EXPECT_EQ(result.exitCode, 2) << arguments.back();
        EXPECT_FALSE(std::filesystem::exists(out));
    }
}

}  // namespace
}  // namespace subscan
