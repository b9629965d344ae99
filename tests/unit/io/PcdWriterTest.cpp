#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/PcdWriter.h"
#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

std::string headerOf(const std::filesystem::path& path) {
    std::ifstream stream(path, std::ios::binary);
    std::string header, line;
    while (std::getline(stream, line)) {
        header += line + "\n";
        if (line.starts_with("DATA")) {
            break;
        }
    }
    return header;
}

TEST(PcdWriterTest, UtmCloudIsWrittenWithDoublesAndReadsBack) {
    const test::TempDir dir;
    const PointCloud cloud = test::utmCloudWithEveryAttribute();
    const auto path = dir / "utm.pcd";
    writePcd(path, cloud);
    EXPECT_EQ(headerOf(path),
              "# .PCD v0.7 - Point Cloud Data file format (written by subscan)\n"
              "VERSION 0.7\n"
              "FIELDS x y z rgb intensity normal_x normal_y normal_z\n"
              "SIZE 8 8 8 4 4 4 4 4\n"
              "TYPE F F F U F F F F\n"
              "COUNT 1 1 1 1 1 1 1 1\n"
              "WIDTH 5\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 5\nDATA binary\n");
    // Header, then 5 records of 3 doubles and 5 four-byte values.
    EXPECT_EQ(std::filesystem::file_size(path), headerOf(path).size() + 5 * (3 * 8 + 5 * 4));

    const LoadedScan read = loadScan(path.string());
    EXPECT_TRUE(read.warnings.empty()) << read.warnings.front();
    // Doubles in the file; in memory floats relative to the centre, exact here (multiples of
    // 0.25 m within 5 m of it), but allow half a float step at 5 m (2.4e-7) as in general.
    test::expectPositionsNear(read.cloud, cloud, 2.4e-7);
    EXPECT_EQ(read.cloud.colors, cloud.colors);
    // Floats written and read as floats: bit for bit.
    EXPECT_EQ(read.cloud.intensities, cloud.intensities);
    EXPECT_EQ(read.cloud.normals, cloud.normals);
}

TEST(PcdWriterTest, TheSensorIsTheViewpoint) {
    // A scan's sensor written as VIEWPOINT, read back as the sensor: it was always the origin,
    // so normals estimated from the written file faced another point (found from outside).
    const test::TempDir dir;
    const PointCloud cloud = test::utmCloudWithEveryAttribute();
    const glm::dvec3 sensor(500001.25, 5400002.5, 31.75);
    const auto path = dir / "seen.pcd";
    writePcd(path, cloud, sensor);
    EXPECT_THAT(headerOf(path), HasSubstr("VIEWPOINT 500001.25 5400002.5 31.75 1 0 0 0\n"));
    const LoadedScan read = loadScan(path.string());
    ASSERT_TRUE(read.sensor.has_value());
    EXPECT_EQ(read.sensor->position, sensor);  // printed with 17 digits: exact
}

TEST(PcdWriterTest, SmallCoordinatesAreFloatAndOnlyPresentFieldsAreWritten) {
    const test::TempDir dir;
    PointCloudBuilder builder({.color = true}, 2);
    for (const double x : {0.125, -0.5}) {
        PointRecord record;
        record.position = {x, 1.0, 2.0};
        record.color = {255, 0, 17, 255};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const auto path = dir / "small.pcd";
    writePcd(path, cloud);
    const std::string header = headerOf(path);
    EXPECT_THAT(header, HasSubstr("FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\n"));

    // The packed colour is 0x00RRGGBB, as PCL packs it: check the bytes of the first record.
    std::ifstream stream(path, std::ios::binary);
    stream.seekg(static_cast<std::streamoff>(header.size() + 12));
    unsigned char rgb[4] = {};
    stream.read(reinterpret_cast<char*>(rgb), 4);
    EXPECT_EQ(rgb[0], 17);  // little-endian: blue first
    EXPECT_EQ(rgb[1], 0);
    EXPECT_EQ(rgb[2], 255);
    EXPECT_EQ(rgb[3], 0);

    const LoadedScan read = loadScan(path.string());
    // Float in the file; every coordinate here is exact in float.
    test::expectPositionsNear(read.cloud, cloud, 0.0);
    EXPECT_EQ(read.cloud.colors, cloud.colors);
    EXPECT_FALSE(read.cloud.hasNormals());
    EXPECT_FALSE(read.cloud.hasIntensities());
}

TEST(PcdWriterTest, UnwritablePathIsAnErrorNamingIt) {
    test::expectUnwritablePathIsAnErrorNamingIt(
        [](const std::filesystem::path& path) {
            writePcd(path, test::utmCloudWithEveryAttribute());
        },
        "out.pcd");
}

}  // namespace
}  // namespace subscan
