// Streamed sources (COPC, EPT) against the real lone star scan: PDAL's COPC file and its EPT
// copy hold the points of lone_star.laz; the node selection keeps to its budget and its order;
// a view at a budget that takes every point renders the same depth as the whole file; a
// damaged node is left out with one warning.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <tuple>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include "core/Camera.h"
#include "core/Error.h"
#include "io/Image.h"
#include "io/ScanLoader.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "support/TestSupport.h"

namespace subscan::lod {
namespace {

using ::testing::HasSubstr;

/// Positions in quarter millimetres, sorted: the three files store them on that grid (scale
/// 0.00025, offsets on it too), and float positions about an origin tens of metres away are
/// within 2e-6 m of them, far from the half step.
std::vector<std::tuple<long long, long long, long long>> gridPositions(const PointCloud& cloud) {
    std::vector<std::tuple<long long, long long, long long>> keys;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = cloud.fileCoordinates(i) / 0.00025;
        keys.emplace_back(std::llround(p.x), std::llround(p.y), std::llround(p.z));
    }
    std::sort(keys.begin(), keys.end());
    return keys;
}

std::vector<std::size_t> everyNode(const NodeSource& source) {
    std::vector<std::size_t> all(source.nodes().size());
    std::iota(all.begin(), all.end(), std::size_t{0});
    return all;
}

/// A copy of the shared data's `from` at `to` that the test may damage (the originals are
/// read-only).
void writableCopy(const std::filesystem::path& from, const std::filesystem::path& to) {
    std::filesystem::copy(from, to, std::filesystem::copy_options::recursive);
    for (const auto& entry : std::filesystem::recursive_directory_iterator(to)) {
        std::filesystem::permissions(entry.path(), std::filesystem::perms::owner_write,
                                     std::filesystem::perm_options::add);
    }
}

Camera framing(const NodeSource& source, double yaw, double pitch) {
    OrbitView orbit;
    orbit.yawDegrees = yaw;
    orbit.pitchDegrees = pitch;
    orbit.up = UpAxis::Z;
    return orbitCamera(source.info().bounds, orbit, 512, 384, 45.0);
}

TEST(StreamedSourceDataTest, CopcAndEptHoldTheWholeFilesPoints) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const PointCloud whole = loadScan((data / "lone_star.laz").string()).cloud;
    const auto expected = gridPositions(whole);
    for (const std::filesystem::path& path :
         {data / "lone_star.copc.laz", data / "ept" / "lone-star-laszip"}) {
        SCOPED_TRACE(path.string());
        const std::unique_ptr<NodeSource> source = openStreamed(path.string(), LodMode::On);
        ASSERT_TRUE(source);
        EXPECT_EQ(source->info().points, whole.size());
        EXPECT_EQ(source->info().format, "las");
        // Every node's tile or chunk holds the count its hierarchy gives.
        for (std::size_t i = 0; i < source->nodes().size(); ++i) {
            EXPECT_EQ(source->load(i).size(), source->nodes()[i].pointCount) << i;
        }
        std::vector<std::string> warnings;
        const PointCloud streamed = loadNodes(*source, everyNode(*source), warnings);
        EXPECT_TRUE(warnings.empty());
        EXPECT_EQ(gridPositions(streamed), expected);
    }
}

TEST(StreamedSourceDataTest, TheSelectionKeepsToItsBudgetAndOrder) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const std::unique_ptr<NodeSource> source = openCopc(data / "lone_star.copc.laz");
    const std::span<const StreamedNode> nodes = source->nodes();
    const Camera camera = framing(*source, 30.0, 35.0);

    // A budget that takes every point takes every node of the framed survey.
    EXPECT_EQ(selectNodes(*source, camera, source->info().points).size(), nodes.size());

    for (const std::uint64_t budget : {1ull, 100'000ull, 250'000ull}) {
        SCOPED_TRACE(budget);
        const std::vector<std::size_t> chosen = selectNodes(*source, camera, budget);
        ASSERT_FALSE(chosen.empty());
        EXPECT_EQ(chosen.front(), 0u);  // the root, whatever the budget
        std::uint64_t points = 0;
        for (std::size_t i = 0; i < chosen.size(); ++i) {
            points += nodes[chosen[i]].pointCount;
            if (i == 0) {
                continue;
            }
            // Its parent was chosen before it.
            const laz::VoxelKey& key = nodes[chosen[i]].key;
            const std::size_t parent =
                source->find({key.level - 1, key.x >> 1, key.y >> 1, key.z >> 1});
            const auto before = std::find(chosen.begin(), chosen.begin() + i, parent);
            EXPECT_NE(before, chosen.begin() + i) << "node " << chosen[i];
        }
        EXPECT_LE(points, std::max(budget, nodes[0].pointCount));
        EXPECT_EQ(selectNodes(*source, camera, budget), chosen);  // deterministic
    }

    // Looking away from the survey: nothing but the root.
    Camera behind = camera;
    const glm::dvec3 eye = camera.eye();
    behind.view = glm::lookAt(eye, eye + (eye - source->info().cube.center), glm::dvec3(0, 0, 1));
    const std::vector<std::size_t> none = selectNodes(*source, behind, source->info().points);
    EXPECT_EQ(none, std::vector<std::size_t>{0});
}

TEST(StreamedSourceDataTest, TheNodeHoldingTheEyeComesFirst) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const std::unique_ptr<NodeSource> source = openCopc(data / "lone_star.copc.laz");
    const std::span<const StreamedNode> nodes = source->nodes();
    // The eye inside the deepest node's cube, looking across the survey.
    const std::size_t deepest = nodes.size() - 1;
    const OctreeCube& cube = source->info().cube;
    const laz::VoxelKey& key = nodes[deepest].key;
    const double side = 2.0 * cube.halfSize / static_cast<double>(1 << key.level);
    const glm::dvec3 inside =
        cube.center - cube.halfSize + (glm::dvec3(key.x, key.y, key.z) + 0.5) * side;
    OrbitView orbit;
    orbit.up = UpAxis::Z;
    orbit.center = cube.center;
    orbit.distance = glm::length(inside - cube.center);
    const glm::dvec2 angles = orbitAngles(inside - cube.center, UpAxis::Z);
    orbit.yawDegrees = angles.x;
    orbit.pitchDegrees = angles.y;
    Camera camera = orbitCamera(source->info().bounds, orbit, 512, 384, 60.0);
    camera.nearPlane = 0.01;
    camera.farPlane = 4.0 * cube.halfSize;
    ASSERT_LT(glm::length(camera.eye() - inside), 1e-6 * side);
    // Its ancestors first (parents before children), then it, before any other node.
    const std::vector<std::size_t> chosen = selectNodes(*source, camera, source->info().points);
    ASSERT_GT(chosen.size(), static_cast<std::size_t>(key.level));
    EXPECT_EQ(chosen[static_cast<std::size_t>(key.level)], deepest);
}

TEST(StreamedSourceDataTest, TheSameDepthAsTheWholeFileAtAFullBudget) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir folder;
    const auto render = [&](const std::filesystem::path& scan, const std::string& name,
                            const std::vector<std::string>& extra) {
        std::vector<std::string> arguments{"render",
                                           scan.string(),
                                           "--mode",
                                           "surface",
                                           "-o",
                                           (folder / (name + ".png")).string(),
                                           "--export-buffers",
                                           (folder / name).string()};
        arguments.insert(arguments.end(), extra.begin(), extra.end());
        const test::CommandResult result = test::runSubscan(arguments);
        EXPECT_EQ(result.exitCode, 0) << result.err;
        return readPfm(folder / name / "depth.pfm");
    };
    const ImageF whole =
        render(data / "lone_star.laz", "whole",
               {"--width", "512", "--height", "384", "--yaw", "30", "--pitch", "35"});
    const std::string camera = (folder / "whole" / "camera.json").string();
    // A budget of every point, whatever the renderer's default.
    const ImageF copc = render(data / "lone_star.copc.laz", "copc",
                               {"--camera", camera, "--point-budget", "518862"});
    const ImageF ept = render(data / "ept" / "lone-star-laszip", "ept",
                              {"--camera", camera, "--point-budget", "518862"});
    const ImageF copcWhole =
        render(data / "lone_star.copc.laz", "copc-off", {"--camera", camera, "--lod", "off"});
    ASSERT_EQ(copc.values.size(), whole.values.size());
    ASSERT_EQ(ept.values.size(), whole.values.size());
    ASSERT_EQ(copcWhole.values.size(), whole.values.size());
    std::size_t all = 0, covered = 0, equal = 0, streamedDiffers = 0;
    const auto on = [](float depth) { return std::isfinite(depth) && depth > 0.0f; };
    for (std::size_t i = 0; i < whole.values.size();
         i += static_cast<std::size_t>(whole.channels)) {
        const float a = whole.values[i], b = copc.values[i], c = ept.values[i];
        covered += on(a);
        if (!(on(a) && on(b) && on(c))) {
            continue;
        }
        ++all;
        // The same points about other origins: float positions round differently, by about
        // 1e-7 of the depth (48 m here; 1.1e-5 m measured).
        const float tolerance = 1e-6f * a;
        equal += std::abs(a - b) <= tolerance && std::abs(a - c) <= tolerance;
        streamedDiffers += std::abs(copcWhole.values[i] - b) > tolerance;
    }
    ASSERT_GT(covered, 30'000u);
    // The same file streamed and whole: the same points about other origins, whose rounding
    // can tip a point's visibility where its spacing ratio decides how far the hidden point
    // search goes, and pull-push then carries the change of depth over the pixels around it
    // (11 of about 35,000 pixels measured at the view before the exact framing; at its view,
    // 2026-12-06: 6 pixels of the visibility stage, 116 of 35,237 of the depth).
    EXPECT_LT(static_cast<double>(streamedDiffers), 0.005 * static_cast<double>(all));
    // All three cover nearly every pixel the whole file does (7 and 15 pixels of 35,454 differ
    // at the outline: points in another order tie differently in the rasterizer).
    EXPECT_GT(static_cast<double>(all), 0.999 * static_cast<double>(covered));
    // Equal depth where all three cover, but for the EPT copy's few ties and the rounding that
    // tips visibility where the hidden point search follows an occluder's spacing (16 pixels
    // measured before that search, 79 of 35,474 with it; 198 of 35,237 at the exact
    // framing's view, 2026-12-06).
    EXPECT_GT(static_cast<double>(equal), 0.993 * static_cast<double>(all));
}

TEST(StreamedSourceDataTest, ADamagedNodeIsLeftOutWithOneWarning) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir folder;
    const std::filesystem::path ept = folder / "ept";
    writableCopy(data / "ept" / "lone-star-laszip", ept);
    // A missing tile, a truncated one, and one whose count the hierarchy misstates.
    std::filesystem::remove(ept / "ept-data" / "3-5-4-3.laz");
    std::filesystem::resize_file(ept / "ept-data" / "1-0-0-0.laz", 5000);
    std::filesystem::copy_file(ept / "ept-data" / "1-0-1-0.laz", ept / "ept-data" / "1-1-0-0.laz",
                               std::filesystem::copy_options::overwrite_existing);
    // And a hierarchy page that is not JSON: the nodes it lists (2-2-2-2 and 3-5-4-4, 80,725
    // points) are left out, and ept.json's count no longer matches.
    std::ofstream(ept / "ept-hierarchy" / "2-2-2-2.json") << "{\"2-2-2-2\": 59398,";
    const std::unique_ptr<NodeSource> source = openEpt(ept);
    ASSERT_EQ(source->info().warnings.size(), 2u)
        << ::testing::PrintToString(source->info().warnings);
    EXPECT_THAT(source->info().warnings[0],
                HasSubstr("2-2-2-2.json: is not valid JSON; the nodes it lists are left out"));
    EXPECT_EQ(source->info().warnings[1],
              "ept.json declares 518862 points, but its hierarchy lists 438137; the "
              "hierarchy's are read");
    EXPECT_EQ(source->find({3, 5, 4, 4}), source->nodes().size());
    std::vector<std::string> warnings;
    const PointCloud cloud = loadNodes(*source, everyNode(*source), warnings);
    ASSERT_EQ(warnings.size(), 3u) << ::testing::PrintToString(warnings);
    EXPECT_THAT(warnings[0], HasSubstr("node 1-0-0-0: "));
    EXPECT_THAT(warnings[1], HasSubstr("node 1-1-0-0: its tile holds 25867 points, but the "
                                       "hierarchy says 37195; it is left out"));
    EXPECT_THAT(warnings[2], HasSubstr("node 3-5-4-3: its tile "));
    EXPECT_THAT(warnings[2], HasSubstr("is missing; it is left out"));
    EXPECT_EQ(cloud.size(), 518'862u - 80'725 - 22'108 - 37'195 - 18'266);

    // The command renders the rest and says so once for the hierarchy and once per node it
    // reads: at 64 x 48 pixels the view never reads node 3-5-4-3 (its parent's points lie
    // closer than half a pixel).
    const test::CommandResult result =
        test::runSubscan({"render", ept.string(), "-o", (folder / "out.png").string(), "--width",
                          "64", "--height", "48"});
    EXPECT_EQ(result.exitCode, 0) << result.err;
    EXPECT_EQ(test::lineCount(result.err), 4u) << result.err;
    EXPECT_THAT(result.err, HasSubstr("the nodes it lists are left out"));
    EXPECT_THAT(result.err, HasSubstr("node 1-0-0-0: "));
    EXPECT_THAT(result.err, HasSubstr("node 1-1-0-0: its tile holds"));
    EXPECT_TRUE(std::filesystem::exists(folder / "out.png"));
}

TEST(StreamedSourceDataTest, AMissingRootOrBadBoundsStillShowTheRest) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir folder;
    const auto picture = [&](const std::filesystem::path& scan) {
        const test::CommandResult result =
            test::runSubscan({"render", scan.string(), "-o", (folder / "out.png").string(),
                              "--width", "64", "--height", "48", "--background", "#000000"});
        const Image8 image = result.exitCode == 0 ? readPng(folder / "out.png") : Image8{};
        std::size_t drawn = 0;
        for (std::size_t i = 0; i < image.pixels.size(); i += 4) {
            drawn += image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2] > 0;
        }
        return std::pair{result, drawn};
    };
    // The root tile missing: the overview takes the next level, the view leaves the root out.
    const std::filesystem::path ept = folder / "ept";
    writableCopy(data / "ept" / "lone-star-laszip", ept);
    std::filesystem::remove(ept / "ept-data" / "0-0-0-0.laz");
    const auto [rootless, rootlessDrawn] = picture(ept);
    EXPECT_EQ(rootless.exitCode, 0) << rootless.err;
    EXPECT_EQ(test::lineCount(rootless.err), 1u) << rootless.err;
    EXPECT_THAT(rootless.err, HasSubstr("node 0-0-0-0: its tile "));
    EXPECT_GT(rootlessDrawn, 300u);  // of 3,072 pixels: the scan covers about a fifth

    // No tile at all: one sentence, no picture.
    std::filesystem::remove_all(ept / "ept-data");
    const auto [none, noneDrawn] = picture(ept);
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_EQ(test::lineCount(none.err), 1u) << none.err;
    EXPECT_THAT(none.err, HasSubstr("none of the 13 nodes it needs could be read"));

    // A COPC header whose bounds are zeros: the octree's cube frames the view instead.
    const std::filesystem::path copc = folder / "zeros.copc.laz";
    std::filesystem::copy_file(data / "lone_star.copc.laz", copc);
    std::filesystem::permissions(copc, std::filesystem::perms::owner_write,
                                 std::filesystem::perm_options::add);
    {
        std::fstream file(copc, std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(179);  // max x, min x, max y, min y, max z, min z: six doubles
        const std::string zeros(48, '\0');
        file.write(zeros.data(), static_cast<std::streamsize>(zeros.size()));
    }
    const auto [zeroed, zeroedDrawn] = picture(copc);
    EXPECT_EQ(zeroed.exitCode, 0) << zeroed.err;
    EXPECT_THAT(zeroed.err, HasSubstr("do not lie in the COPC octree's cube; the cube's are used"));
    EXPECT_GT(zeroedDrawn, 100u);  // the cube is larger than the bounds: a smaller picture
}

TEST(StreamedSourceDataTest, InfoDescribesAStreamedSourceFromItsHierarchy) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    for (const std::filesystem::path& path :
         {data / "lone_star.copc.laz", data / "ept" / "lone-star-laszip"}) {
        SCOPED_TRACE(path.string());
        const test::CommandResult streamed = test::runSubscan({"info", path.string(), "--json"});
        const test::CommandResult whole =
            test::runSubscan({"info", path.string(), "--json", "--lod", "off"});
        ASSERT_EQ(streamed.exitCode, 0) << streamed.err;
        ASSERT_EQ(whole.exitCode, 0) << whole.err;
        const nlohmann::json a = nlohmann::json::parse(streamed.out);
        const nlohmann::json b = nlohmann::json::parse(whole.out);
        EXPECT_EQ(a["points"], b["points"]);
        EXPECT_EQ(a["attributes"], b["attributes"]);
        std::uint64_t levels = 0;
        for (const auto& count : a["level_points"]) {
            levels += count.get<std::uint64_t>();
        }
        EXPECT_EQ(levels, 518'862u);
        // The header's (COPC) or the sources' (EPT) bounds against the points': equal to the
        // files' 0.25 mm grid.
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(a["bounds_min"][axis].get<double>(), b["bounds_min"][axis].get<double>(),
                        0.00025);
            EXPECT_NEAR(a["bounds_max"][axis].get<double>(), b["bounds_max"][axis].get<double>(),
                        0.00025);
        }
        // One dense node's spacing against the whole cloud's: within 15 % (the scan's density
        // varies; measured 0.0317 for the COPC file's and 0.0337 for the EPT copy's node
        // against 0.0298).
        EXPECT_NEAR(a["spacing"].get<double>(), b["spacing"].get<double>(),
                    0.15 * b["spacing"].get<double>());
        EXPECT_FALSE(b.contains("level_points"));
    }
}

TEST(StreamedSourceDataTest, WhatCannotBeStreamedIsOneSentence) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    EXPECT_EQ(openStreamed((data / "lone_star.laz").string(), LodMode::Auto), nullptr);
    EXPECT_EQ(openStreamed((data / "lone_star.copc.laz").string(), LodMode::Off), nullptr);
    const test::TempDir dir;
    const test::CommandResult result =
        test::runSubscan({"render", (data / "bun_zipper_res4.ply").string(), "--lod", "on", "-o",
                          (dir / "out.png").string()});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, HasSubstr("is neither a COPC file nor an EPT dataset"));
    EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
    EXPECT_THROW(parseLodMode("sometimes"), Error);
    EXPECT_EQ(test::errorMessage(
                  [&] { openStreamed((data / "no-such-survey.copc.laz").string(), LodMode::On); }),
              (data / "no-such-survey.copc.laz").string() + ": no such file or folder");
}

}  // namespace
}  // namespace subscan::lod
