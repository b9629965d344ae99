#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "io/ScanLoader.h"
#include "scan/SyntheticScenes.h"
#include "scan/VirtualScanner.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::asBytes;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string loadError(const std::string& source) {
    try {
        loadScan(source);
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "loading " << source << " did not throw";
    return {};
}

TEST(ScanLoaderTest, ContentWinsOverExtension) {
    EXPECT_EQ(detectFormat(asBytes("ply\nformat ascii 1.0\n"), "scan.las"), ScanFormat::Ply);
    EXPECT_EQ(detectFormat(asBytes(std::string_view("LASF\0\0", 6)), "scan.ply"), ScanFormat::Las);
    EXPECT_EQ(detectFormat(asBytes("ASTM-E57"), "scan.xyz"), ScanFormat::E57);
    EXPECT_EQ(detectFormat(asBytes("# .PCD v.7 - Point Cloud Data\nVERSION .7\n"), "a.txt"),
              ScanFormat::Pcd);
    EXPECT_EQ(detectFormat(asBytes("VERSION 0.7\nFIELDS x y z\n"), "noext"), ScanFormat::Pcd);
    for (const char* off :
         {"OFF\n4 2 0\n", "COFF\r\n", "STCNOFF 4 2 0\n", "OFF", "OFF BINARY\n", "OFFBINARY\n"}) {
        EXPECT_EQ(detectFormat(asBytes(off), "mesh.txt"), ScanFormat::Off) << off;
    }
    // Not OFF: other text that merely contains the letters.
    EXPECT_EQ(detectFormat(asBytes("OFFSET 1 2 3\n"), "a.txt"), ScanFormat::Xyz);
    EXPECT_EQ(detectFormat(asBytes("x OFF\n"), "a.txt"), ScanFormat::Xyz);
}

TEST(ScanLoaderTest, ExtensionDecidesWhenContentIsUnclear) {
    EXPECT_EQ(detectFormat(asBytes("garbage"), "scan.PLY"), ScanFormat::Ply);
    EXPECT_EQ(detectFormat(asBytes("garbage"), "scan.laz"), ScanFormat::Las);
    EXPECT_EQ(detectFormat(asBytes("garbage"), "scan.pcd"), ScanFormat::Pcd);
    EXPECT_EQ(detectFormat(asBytes("garbage"), "scan.e57"), ScanFormat::E57);
    EXPECT_EQ(detectFormat(asBytes("garbage"), "mesh.OFF"), ScanFormat::Off);
    for (const char* name : {"a.xyz", "a.pts", "a.txt", "a.csv", "a.asc"}) {
        EXPECT_EQ(detectFormat(asBytes("garbage"), name), ScanFormat::Xyz) << name;
    }
    EXPECT_EQ(detectFormat(asBytes("garbage\x01\x02"), "scan.bin"), ScanFormat::Unknown);
}

TEST(ScanLoaderTest, ErrorsNameTheFile) {
    const test::TempDir dir;
    const auto empty = dir.write("empty.ply", "");
    EXPECT_EQ(loadError(empty.string()), empty.string() + ": the file is empty");
    const auto unknown = dir.write("scan.bin", std::string("\x7f\x01\x02garbage", 10));
    EXPECT_THAT(loadError(unknown.string()),
                AllOf(StartsWith(unknown.string() + ": "), HasSubstr("format is unknown")));
    const auto e57 = dir.write("scan.e57", "ASTM-E57 and more");
    EXPECT_THAT(loadError(e57.string()),
                AllOf(StartsWith(e57.string() + ": "),
                      HasSubstr("fewer than the 48-byte E57 file header (file truncated?)")));
    // An OFF mesh cut short: its reader's sentence, after the file's name.
    const auto off = dir.write("mesh.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n");
    EXPECT_EQ(loadError(off.string()),
              off.string() + ": the OFF file ends before vertex 4 of 4 (file truncated?)");
    EXPECT_THAT(loadError((dir / "missing.ply").string()),
                HasSubstr("missing.ply: cannot open the file: No such file"));
    EXPECT_THAT(loadError(dir.path().string()), HasSubstr("is a directory"));
}

TEST(ScanLoaderTest, AFileThatShrinksWhileItIsReadIsOneSentenceNotASignal) {
    // A binary PLY of 200,000 points (2.4 MB); the loader's first progress report, before the
    // first vertex, cuts the file to 4 KiB, as another program rewriting it would. The pages
    // past the new end are gone from the mapping: without the guard, reading them is SIGBUS.
    const test::TempDir dir;
    constexpr int kPoints = 200000;
    std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                      std::to_string(kPoints) +
                      "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    for (int i = 0; i < kPoints; ++i) {
        for (const float value : {float(i), 1.0f, 2.0f}) {
            test::appendBytes(ply, value);
        }
    }
    const auto path = dir.write("shrinking.ply", ply);
    bool cut = false;
    try {
        loadScan(path.string(), [&](double) {
            if (!cut) {
                std::filesystem::resize_file(path, 4096);
                cut = true;
            }
        });
        FAIL() << "the shortened file loaded";
    } catch (const Error& error) {
        EXPECT_EQ(std::string(error.what()),
                  path.string() +
                      ": the file became shorter while it was read (another program "
                      "truncated or rewrote it); read it again once it is complete");
    }
    EXPECT_TRUE(cut) << "the reader never reported progress, so nothing was cut";
    // The same file, now complete in its shorter form, is an ordinary truncated PLY.
    EXPECT_THAT(loadError(path.string()), HasSubstr("truncated"));
}

TEST(ScanLoaderTest, NormalsThatAreAllZeroCountAsAbsent) {
    // Exporters that write zeros into the normal fields: the surface was shaded flat with them.
    auto xyz = [](const std::string& lines) { return "x y z nx ny nz\n" + lines; };
    const std::string zero = xyz("0 0 0 0 0 0\n1 0 0 0 0 0\n0 1 0 0 0 0\n");
    const LoadedScan zeros = decodeScan(asBytes(zero), ScanFormat::Xyz);
    EXPECT_FALSE(zeros.cloud.hasNormals());
    EXPECT_THAT(zeros.warnings, ::testing::Contains(HasSubstr("normals are all zero")));
    // One real normal among zeros: the file's are kept (the others are points without one).
    const std::string some = xyz("0 0 0 0 0 0\n1 0 0 0 0 1\n0 1 0 0 0 0\n");
    const LoadedScan kept = decodeScan(asBytes(some), ScanFormat::Xyz);
    ASSERT_TRUE(kept.cloud.hasNormals());
    EXPECT_EQ(kept.cloud.normals[1], glm::vec3(0, 0, 1));
    EXPECT_TRUE(kept.warnings.empty());
}

TEST(ScanLoaderTest, SyntheticScenes) {
    const LoadedScan sphere = loadScan("synthetic:sphere?points=500");
    EXPECT_EQ(sphere.format, "synthetic");
    ASSERT_EQ(sphere.cloud.size(), 500u);
    for (std::size_t i = 0; i < sphere.cloud.size(); ++i) {
        // Points are generated in double and stored as float: 1e-6 covers float rounding.
        EXPECT_NEAR(glm::length(sphere.cloud.fileCoordinates(i)), 1.0, 1e-6);
    }
    EXPECT_THAT(loadError("synthetic:teapot"), HasSubstr("no built-in scene 'teapot'"));
    EXPECT_THAT(loadError("synthetic:sphere?points=0"), HasSubstr("not a point count"));
    EXPECT_THAT(loadError("synthetic:sphere?points=12x"), HasSubstr("not a point count"));
    EXPECT_THAT(loadError("synthetic:sphere?size=3"),
                HasSubstr("unknown synthetic scene parameter"));
    EXPECT_FALSE(sphere.sensor);  // an object scan has no one place it was taken from
}

TEST(ScanLoaderTest, ASyntheticStationRecordsWhereItStood) {
    const LoadedScan scan = loadScan("synthetic:outdoor-station?points=2000");
    ASSERT_TRUE(scan.sensor);
    const SyntheticSource source = makeSyntheticSource("outdoor-station?points=2000");
    EXPECT_EQ(scan.sensor->position, stationPosition(*source.scene, source.scanner.station));
    EXPECT_FALSE(loadScan("synthetic:outdoor-airborne?points=2000").sensor);
}

}  // namespace
}  // namespace subscan
