#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ScanLoader.h"
#include "io/XyzWriter.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

TEST(XyzWriterTest, UtmCloudReadsBackExactly) {
    const test::TempDir dir;
    const PointCloud cloud = test::utmCloudWithEveryAttribute();
    const auto path = dir / "utm.xyz";
    writeXyz(path, cloud);
    const std::string text = test::fileBytes(path);
    // The header names the columns; the numbers are as short as round-tripping allows.
    EXPECT_THAT(text,
                ::testing::StartsWith("X Y Z Red Green Blue Intensity NormalX NormalY NormalZ\n"
                                      "512345.25 5432109.5 97 0 200 255 0 0 1 0\n"
                                      "512355.25 5432109.5 97 60 200 254 1.25 "));

    const LoadedScan read = loadScan(path.string());
    EXPECT_TRUE(read.warnings.empty()) << read.warnings.front();
    EXPECT_EQ(read.formatDetail, "text: x y z r g b i nx ny nz");
    // Shortest round-trip text gives back the same doubles; in memory floats relative to the
    // centre, exact here, but allow half a float step at 5 m (2.4e-7) as in general.
    test::expectPositionsNear(read.cloud, cloud, 2.4e-7);
    EXPECT_EQ(read.cloud.colors, cloud.colors);
    // The shortest text of a float reads back as that float.
    EXPECT_EQ(read.cloud.intensities, cloud.intensities);
    EXPECT_EQ(read.cloud.normals, cloud.normals);
}

TEST(XyzWriterTest, PositionsOnly) {
    const test::TempDir dir;
    PointCloudBuilder builder({}, 2);
    for (const double x : {0.1, -1e-7}) {
        PointRecord record;
        record.position = {x, 2.0, 3.0};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const auto path = dir / "plain.xyz";
    writeXyz(path, cloud);
    const glm::dvec3 first = cloud.fileCoordinates(0);
    EXPECT_EQ(test::fileBytes(path),
              fmt::format("X Y Z\n{} 2 3\n{} 2 3\n", first.x, cloud.fileCoordinates(1).x));
    const LoadedScan read = loadScan(path.string());
    EXPECT_FALSE(read.cloud.hasColors());
    EXPECT_FALSE(read.cloud.hasIntensities());
    // The same doubles, then float relative to a centre 0.05 away: a float step there is 4e-9.
    test::expectPositionsNear(read.cloud, cloud, 1e-8);
}

TEST(XyzWriterTest, UnwritablePathIsAnErrorNamingIt) {
    test::expectUnwritablePathIsAnErrorNamingIt(
        [](const std::filesystem::path& path) {
            writeXyz(path, test::utmCloudWithEveryAttribute());
        },
        "out.xyz");
}

}  // namespace
}  // namespace subscan
