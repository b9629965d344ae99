// `subscan info` and `subscan render` on every file of the shared real-scan folder
// (../shared/data or $SUBSCAN_TEST_DATA; see its README). Skipped, visibly, when it is absent.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/Camera.h"
#include "core/Coloring.h"
#include "core/SensorView.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

struct Expected {
    const char* file;
    std::uint64_t points;  // 0: the file must be refused
    std::uint64_t faces;
    const char* refusal;
    /// The share of the pixels within the scan's projected bounds that `subscan render` draws
    /// at 96 x 72 (EveryReadableFileRenders), measured 2026-12-03 on llvmpipe.
    double drawnShare;
};

// Counts from the folder's README (itself checked against the file bodies); face counts from
// the PLY headers. The drawn shares: drawn pixels / projected bounds' pixels, as measured.
const Expected kFiles[] = {
    {"ankylosaurus_mesh_rgb.ply", 34820, 69636, nullptr, 0.1850},
    {"autzen_trim.las", 110000, 0, nullptr, 0.2843},
    {"autzen_trim_las14_pf7.las", 110000, 0, nullptr, 0.2843},
    {"autzen_trim.laz", 110000, 0, nullptr, 0.2843},
    {"autzen_utm_binary.pcd", 1065, 0, nullptr, 0.2281},
    {"bun_zipper.ply", 35947, 69451, nullptr, 0.3361},
    {"bun_zipper_res2.ply", 8171, 16301, nullptr, 0.3330},
    {"bun_zipper_res3.ply", 1889, 3851, nullptr, 0.2367},
    {"bun_zipper_res4.ply", 453, 948, nullptr, 0.0775},
    {"bunnyDouble.e57", 30571, 0, nullptr, 0.3406},
    {"bunnyInt32.e57", 30571, 0, nullptr, 0.3406},
    {"bunny_scans_registered.ply", 362272, 0, nullptr, 0.3196},
    {"dragon_stand_registered.ply", 469193, 0, nullptr, 0.3477},
    {"happy_stand_registered.ply", 1099005, 0, nullptr, 0.3873},
    {"isprs_CSite2_orig-utm.pcd", 486800, 0, nullptr, 0.5029},
    {"lone_star.copc.laz", 518862, 0, nullptr, 0.2612},
    {"lone_star.laz", 518862, 0, nullptr, 0.2577},
    {"pcl_bunny_ascii.pcd", 397, 0, nullptr, 0.0638},
    {"room_scan1.pcd", 112586, 0, nullptr, 0.2131},
    {"simple.las", 1065, 0, nullptr, 0.1696},
    // 307,200 organised points, of which 97,920 are NaN ("no measurement") and dropped.
    {"table_scene_mug_stereo_textured.pcd", 209280, 0, nullptr, 0.1671},
};

nlohmann::json info(const std::filesystem::path& file) {
    const auto result = runSubscan({"info", file.string(), "--json"});
    EXPECT_EQ(result.exitCode, 0) << file << ": " << result.err;
    return result.exitCode == 0 ? nlohmann::json::parse(result.out) : nlohmann::json{};
}

/// The vertex count a PLY header declares, read here without subscan's reader.
std::uint64_t headerVertexCount(const std::filesystem::path& file) {
    std::ifstream stream(file, std::ios::binary);
    std::string line;
    while (std::getline(stream, line) && line.rfind("end_header", 0) != 0) {
        if (line.rfind("element vertex ", 0) == 0) {
            return std::stoull(line.substr(15));
        }
    }
    return 0;
}

TEST(RealScansDataTest, InfoGivesExactCountsOrTheClearRefusal) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    for (const Expected& expected : kFiles) {
        SCOPED_TRACE(expected.file);
        const std::filesystem::path file = data / expected.file;
        if (expected.refusal != nullptr) {
            const auto result = runSubscan({"info", file.string(), "--json"});
            EXPECT_EQ(result.exitCode, 1);
            EXPECT_THAT(result.err, HasSubstr(expected.refusal));
            EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1);
            continue;
        }
        const nlohmann::json json = info(file);
        EXPECT_EQ(json["points"], expected.points);
        EXPECT_EQ(json["faces"], expected.faces);
        // "format" names the reader, "las" for LAZ and COPC too; the detail tells them apart.
        const std::string name = expected.file;
        if (name.ends_with(".laz")) {
            EXPECT_EQ(json["format"], "las");
            EXPECT_THAT(json["format_detail"].get<std::string>(),
                        HasSubstr(name.ends_with(".copc.laz") ? "COPC" : "LAZ"));
        }
    }
}

TEST(RealScansDataTest, EveryStanfordRangeScanLoadsWithItsHeaderCount) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // Folder totals from the README; some headers carry stray 'bye' lines.
    const std::pair<const char*, std::uint64_t> folders[] = {
        {"stanford_bunny_scans", 362272},
        {"stanford_dragon_stand", 469193},
        {"stanford_happy_stand", 1099005},
    };
    for (const auto& [folder, total] : folders) {
        std::uint64_t sum = 0;
        for (const auto& entry : std::filesystem::directory_iterator(data / folder)) {
            if (entry.path().extension() != ".ply") {
                continue;
            }
            SCOPED_TRACE(entry.path().filename().string());
            const std::uint64_t declared = headerVertexCount(entry.path());
            EXPECT_EQ(info(entry.path())["points"], declared);
            sum += declared;
        }
        EXPECT_EQ(sum, total) << folder;
    }
}

TEST(RealScansDataTest, RegisteredScanBoundsMatchTheFloatsInTheFile) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    for (const char* name : {"bunny_scans_registered.ply", "dragon_stand_registered.ply",
                             "happy_stand_registered.ply"}) {
        SCOPED_TRACE(name);
        // The layout is known (float x y z, uchar scan_index, little-endian): read it directly.
        std::ifstream stream(data / name, std::ios::binary);
        std::string line;
        while (std::getline(stream, line) && line != "end_header") {
        }
        std::vector<double> low(3, std::numeric_limits<double>::infinity());
        std::vector<double> high(3, -std::numeric_limits<double>::infinity());
        char record[13];
        while (stream.read(record, sizeof(record))) {
            for (int axis = 0; axis < 3; ++axis) {
                float value = 0;
                std::memcpy(&value, record + 4 * axis, sizeof(float));
                low[axis] = std::min(low[axis], static_cast<double>(value));
                high[axis] = std::max(high[axis], static_cast<double>(value));
            }
        }
        const nlohmann::json json = info(data / name);
        // Bounds are kept in double from the file's floats: exact.
        EXPECT_EQ(json["bounds_min"].get<std::vector<double>>(), low);
        EXPECT_EQ(json["bounds_max"].get<std::vector<double>>(), high);
    }
}

TEST(RealScansDataTest, UtmCoordinatesStayInUtm) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const nlohmann::json json = info(data / "isprs_CSite2_orig-utm.pcd");
    // Northing around 5.4e6 m, easting around 5.1e5 m (README).
    EXPECT_NEAR(json["bounds_min"][1].get<double>(), 5.4e6, 1e4);
    EXPECT_NEAR(json["bounds_min"][0].get<double>(), 5.13e5, 1e4);
}

TEST(RealScansDataTest, BunnyE57InDoubleAndScaledIntegerHoldTheSamePoints) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const LoadedScan doubles = loadScan((data / "bunnyDouble.e57").string());
    const LoadedScan integers = loadScan((data / "bunnyInt32.e57").string());
    EXPECT_EQ(doubles.formatDetail, "E57 1.0, 1 scan, cartesian Float (double)");
    EXPECT_EQ(integers.formatDetail, "E57 1.0, 1 scan, cartesian ScaledInteger");
    EXPECT_TRUE(doubles.warnings.empty());
    EXPECT_TRUE(integers.warnings.empty());
    ASSERT_EQ(doubles.cloud.size(), 30571u);
    ASSERT_EQ(integers.cloud.size(), 30571u);
    // The Int32 file stores the same scan quantised to its scale of 1e-6 m: a writer rounding
    // to the nearest step moves a coordinate by at most half a step, 5e-7. Both clouds keep
    // floats relative to their centre over a 0.16 m extent, adding ~1e-8. (In these two files
    // the doubles happen to be whole micrometres, so the decoded values agree exactly.)
    constexpr double kTolerance = 5e-7 + 2e-8;
    double largest = 0.0;
    for (std::size_t i = 0; i < doubles.cloud.size(); ++i) {
        const glm::dvec3 d = doubles.cloud.fileCoordinates(i) - integers.cloud.fileCoordinates(i);
        largest = std::max({largest, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    }
    EXPECT_LE(largest, kTolerance);
    // The cartesianBounds both files' XML declares.
    const glm::dvec3 low{-0.094689, 0.040011, -0.061873}, high{0.061009, 0.187321, 0.058799};
    for (const LoadedScan* scan : {&doubles, &integers}) {
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(scan->cloud.bounds.min[axis], low[axis], 1e-12);
            EXPECT_NEAR(scan->cloud.bounds.max[axis], high[axis], 1e-12);
        }
    }
}

TEST(RealScansDataTest, TableSceneFromItsSensorDrawsWhatTheSensorSaw) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto file = data / "table_scene_mug_stereo_textured.pcd";
    const LoadedScan scan = loadScan(file.string());
    ASSERT_EQ(scan.grid.width, 640);
    ASSERT_EQ(scan.grid.height, 480);
    ASSERT_EQ(scan.grid.cellOfPoint.size(), scan.cloud.size());
    const PinholeFit fit = fitPinhole(scan.cloud, scan.grid);
    // A stereo camera's points lie on their pixels' rays up to the file's float rounding:
    // measured 0.0037 pixels RMS; a pinhole that missed by a tenth of a pixel would show.
    EXPECT_LT(fit.rmsErrorPixels, 0.05);
    EXPECT_NEAR(fit.focalX / fit.focalY, 1.0, 1e-3);  // square pixels, as measured: 1.000001

    // Ground truth: the cells the sensor measured. The points mode draws each point in its
    // own cell, so its picture from the sensor view is that mask; the surface also fills the
    // stereo matcher's small holes, but must cover every measured cell.
    std::vector<bool> measured(640 * 480, false);
    for (const std::uint32_t cell : scan.grid.cellOfPoint) {
        measured[cell] = true;
    }
    const test::TempDir dir;
    for (const std::string mode : {"points", "surface"}) {
        SCOPED_TRACE(mode);
        const auto buffers = dir / mode;
        const auto result =
            runSubscan({"render", file.string(), "--view", "sensor", "--mode", mode, "-o",
                        (dir / (mode + ".png")).string(), "--export-buffers", buffers.string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        const ImageF depth = readPfm(buffers / "depth.pfm");
        ASSERT_EQ(depth.width, 640);
        ASSERT_EQ(depth.height, 480);
        int agree = 0, measuredDrawn = 0, measuredCount = 0;
        for (std::size_t cell = 0; cell < measured.size(); ++cell) {
            const bool drawn = std::isfinite(depth.values[cell]);
            agree += drawn == measured[cell];
            measuredCount += measured[cell];
            measuredDrawn += drawn && measured[cell];
        }
        const double agreement = agree / static_cast<double>(measured.size());
        const double coverage = measuredDrawn / static_cast<double>(measuredCount);
        std::printf(
            "%s from the sensor: %.5f of the cells agree with the measured mask, %.5f "
            "of the measured cells drawn\n",
            mode.c_str(), agreement, coverage);
        if (mode == "points") {
            // Measured: every cell agrees. A point on the edge of its cell could fall into the
            // neighbour by float rounding; a camera off by a pixel anywhere would cost ~1 %.
            EXPECT_GT(agreement, 0.9999);
        } else {
            // Measured 0.99969: the hidden-point pass may remove a lone point at a silhouette.
            EXPECT_GT(coverage, 0.999);
        }
    }
    // bench times the same still view: the sensor's image size, not its own default.
    const auto bench = runSubscan({"bench", file.string(), "--view", "sensor", "--frames", "1",
                                   "--warmup", "0", "--modes", "points", "--json"});
    ASSERT_EQ(bench.exitCode, 0) << bench.err;
    const nlohmann::json report = nlohmann::json::parse(bench.out);
    EXPECT_EQ(report["view"], "sensor");
    EXPECT_EQ(report["width"], 640);
    EXPECT_EQ(report["height"], 480);
}

TEST(RealScansDataTest, EveryReadableFileRenders) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir dir;
    for (const Expected& expected : kFiles) {
        if (expected.refusal != nullptr) {
            continue;
        }
        SCOPED_TRACE(expected.file);
        const auto out = dir / "out.png";
        const auto buffers = dir / "buffers";
        // The camera the render used comes back in camera.json, to project the bounds with.
        // Every file whole (--lod off): a streamed COPC file is framed by its top levels and
        // its header's bounds instead (StreamedSourceDataTest).
        const auto result =
            runSubscan({"render", (data / expected.file).string(), "-o", out.string(), "--width",
                        "96", "--height", "72", "--background", "#000000", "--export-buffers",
                        buffers.string(), "--lod", "off"});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        const Image8 image = readPng(out);
        const Camera camera = readCameraFile(buffers / "camera.json");
        const LoadedScan scan = loadScan((data / expected.file).string());
        const Bounds& bounds = scan.cloud.bounds;
        // Auto-framing: the orbit camera of render's defaults (yaw 30°, pitch 20°, Z up for
        // LAS, -Y for the depth camera's table scene) filling the picture with the points'
        // framing box, the same arithmetic, so equal up to a few ulps.
        const UpAxis up = scan.format == "las" ? UpAxis::Z
                          : expected.file == std::string_view("table_scene_mug_stereo_textured.pcd")
                              ? UpAxis::NegativeY
                              : UpAxis::Y;
        OrbitView orbit{30.0, 20.0, std::nullopt, up};
        orbit.framing = Framing::Box;
        orbit.framed = framingBounds(scan.cloud);
        const Camera framed = orbitCamera(bounds, orbit, 96, 72, 45.0);
        for (int column = 0; column < 4; ++column) {
            for (int row = 0; row < 4; ++row) {
                EXPECT_DOUBLE_EQ(camera.view[column][row], framed.view[column][row]);
            }
        }
        EXPECT_DOUBLE_EQ(camera.fovyDegrees, 45.0);
        const glm::ivec4 box = projectedPixelBounds(camera, bounds);
        int drawn = 0, outside = 0;
        for (int y = 0; y < image.height; ++y) {
            for (int x = 0; x < image.width; ++x) {
                const std::size_t i = 4 * static_cast<std::size_t>(y * image.width + x);
                if (image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2] == 0) {
                    continue;
                }
                ++drawn;
                outside += x < box.x || x >= box.z || y < box.y || y >= box.w;
            }
        }
        const int area = (box.z - box.x) * (box.w - box.y);
        ASSERT_GT(area, 0);
        // Every point lies within the bounds, so the points mode draws nothing outside their
        // projection (projectedPixelBounds' 2-pixel margin covers rounding), and at most one
        // pixel per point.
        EXPECT_EQ(outside, 0);
        EXPECT_LE(static_cast<std::uint64_t>(drawn), expected.points);
        // Within the framed bounds the points cover their share (drawn pixels: 349 to 2,403 of
        // 3,168 to 6,912, shares 0.064 to 0.503), a property of the scan and the framing. 10 %
        // either way allows another rasterizer's rounding of points on pixel edges, and fails
        // points drawn bigger (a 2-pixel point alone would double a sparse scan's share),
        // dropped, or black.
        const double share = static_cast<double>(drawn) / area;
        EXPECT_NEAR(share, expected.drawnShare, 0.1 * expected.drawnShare)
            << drawn << " of " << area << " pixels";
    }
}

TEST(RealScansDataTest, ClassificationColoursAutzensGroundWhereItsGroundPointsAre) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir dir;
    const auto source = data / "autzen_trim.las";
    const auto out = dir / "classes.png";
    const auto buffers = dir / "buffers";
    constexpr int kWidth = 160;
    constexpr int kHeight = 120;
    // From straight above, in the points mode: each pixel shows its nearest point's class.
    const auto result = runSubscan(
        {"render", source.string(), "-o", out.string(), "--color", "classification", "--pitch",
         "90", "--width", std::to_string(kWidth), "--height", std::to_string(kHeight),
         "--background", "#000000", "--export-buffers", buffers.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Image8 image = readPng(out);
    ASSERT_EQ(image.width, kWidth);
    const Camera camera = readCameraFile(buffers / "camera.json");

    // Which point each pixel should show, from the scan and camera.json alone (docs/cli.md's
    // pixel convention): the nearest, and with it its class.
    const PointCloud cloud = loadScan(source.string()).cloud;
    ASSERT_TRUE(cloud.hasClassifications());
    const glm::dmat4 projection = camera.projection();
    std::vector<double> nearest(kWidth * kHeight, std::numeric_limits<double>::infinity());
    std::vector<int> expectedClass(kWidth * kHeight, -1);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec4 v = camera.view * glm::dvec4(cloud.fileCoordinates(i), 1.0);
        const glm::dvec4 clip = projection * v;
        const int x = static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * kWidth));
        const int y = static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * kHeight));
        if (x < 0 || y < 0 || x >= kWidth || y >= kHeight || -v.z >= nearest[y * kWidth + x]) {
            continue;
        }
        nearest[y * kWidth + x] = -v.z;
        expectedClass[y * kWidth + x] = cloud.classifications[i];
    }

    const Rgba8 ground = classificationColor(2);
    const Rgba8 unclassified = classificationColor(1);
    int drawn = 0, groundPixels = 0, agreeing = 0, otherColours = 0;
    for (int pixel = 0; pixel < kWidth * kHeight; ++pixel) {
        const std::uint8_t* p = &image.pixels[4 * static_cast<std::size_t>(pixel)];
        if (p[0] + p[1] + p[2] == 0) {
            continue;
        }
        ++drawn;
        const Rgba8 color{p[0], p[1], p[2], 255};
        // The sRGB colours pass through linear light and back (16-bit float in between) and
        // come back to the same byte; no blending is on, so no other colour may appear.
        const bool isGround = color == ground;
        groundPixels += isGround;
        otherColours += !isGround && color != unclassified;
        agreeing += isGround == (expectedClass[pixel] == 2);
    }
    // Autzen from above is mostly covered (a strip of a town), and holds only classes 1 and 2.
    ASSERT_GT(drawn, kWidth * kHeight / 4);
    EXPECT_EQ(otherColours, 0);
    // Ground is 24 % of the points but lies beneath buildings and trees: from above it shows in
    // about 15 % of the drawn pixels (1,015 of 6,741 measured on llvmpipe), and exactly where
    // the projection says a ground point is nearest (all 6,741 agreed; points at nearly equal
    // depth in one pixel may be resolved either way elsewhere). 99 % leaves room for such ties
    // and fails for a shuffled, shifted or missing classification.
    EXPECT_GT(groundPixels, drawn / 10);
    EXPECT_GT(agreeing, 0.99 * drawn) << agreeing << " of " << drawn;
}

// classification is one clear sentence where the scan has none.
TEST(RealScansDataTest, ClassificationOfAScanWithoutOneIsOneSentence) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir dir;
    const auto source = data / "bun_zipper_res4.ply";
    const auto result = runSubscan(
        {"render", source.string(), "-o", (dir / "x.png").string(), "--color", "classification"});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
    EXPECT_THAT(result.err,
                HasSubstr(source.string() + ": the scan has no classification to show"));
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
}

}  // namespace
}  // namespace subscan
