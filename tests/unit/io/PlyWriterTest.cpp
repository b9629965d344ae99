#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "io/PlyWriter.h"
#include "io/ScanLoader.h"
#include "io/WriterSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

std::string headerOf(const std::filesystem::path& path) {
    std::ifstream stream(path, std::ios::binary);
    std::string header, line;
    while (std::getline(stream, line) && line != "end_header") {
        header += line + "\n";
    }
    return header;
}

/// A small cloud with every attribute, around `offset`.
PointCloud everyAttribute(const glm::dvec3& offset, double size, bool translucent = false) {
    PointCloudBuilder builder({.color = true, .normal = true, .intensity = true}, 4, true);
    const glm::dvec3 corners[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.5, 1}};
    for (int i = 0; i < 4; ++i) {
        PointRecord record;
        record.position = offset + size * corners[i];
        record.color = {static_cast<std::uint8_t>(10 * i), 200, static_cast<std::uint8_t>(255 - i),
                        static_cast<std::uint8_t>(translucent && i == 2 ? 128 : 255)};
        record.normal = glm::normalize(glm::vec3(i, 1, -i));
        record.intensity = 0.5f * static_cast<float>(i);
        builder.add(record);
    }
    builder.addTriangle({0, 1, 2});
    builder.addTriangle({3, 2, 1});
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

void expectSameAttributes(const PointCloud& read, const PointCloud& written) {
    ASSERT_EQ(read.size(), written.size());
    EXPECT_EQ(read.colors, written.colors);
    EXPECT_EQ(read.normals, written.normals);  // floats written and read as floats
    EXPECT_EQ(read.intensities, written.intensities);
    EXPECT_EQ(read.triangles, written.triangles);
}

TEST(PlyWriterTest, SmallCoordinatesRoundTripAsFloat) {
    const test::TempDir dir;
    const PointCloud cloud = everyAttribute({-0.3, 0.1, 2.0}, 0.2);
    const auto path = dir / "small.ply";
    writePly(path, cloud);
    const std::string header = headerOf(path);
    EXPECT_THAT(header, HasSubstr("format binary_little_endian 1.0\n"));
    EXPECT_THAT(header, HasSubstr("property float x\n"));
    EXPECT_THAT(header, HasSubstr("property uchar red\n"));
    EXPECT_THAT(header, Not(HasSubstr("alpha")));  // every point is opaque
    EXPECT_THAT(header, HasSubstr("element face 2\nproperty list uchar uint vertex_indices\n"));

    const LoadedScan read = loadScan(path.string());
    expectSameAttributes(read.cloud, cloud);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 expected = cloud.fileCoordinates(i);
        const glm::dvec3 actual = read.cloud.fileCoordinates(i);
        for (int axis = 0; axis < 3; ++axis) {
            // Written as float (half a step at 2.2: 1.2e-7), read back relative to the centre.
            EXPECT_NEAR(actual[axis], expected[axis], 3e-7) << "point " << i;
        }
    }
}

TEST(PlyWriterTest, UtmCoordinatesAreWrittenAsDouble) {
    const test::TempDir dir;
    const glm::dvec3 utm(512345.25, 5432109.5, 97.0);
    const PointCloud cloud = everyAttribute(utm, 10.0, true);
    EXPECT_TRUE(needsDoubleCoordinates(cloud));
    const auto path = dir / "utm.ply";
    writePly(path, cloud);
    const std::string header = headerOf(path);
    EXPECT_THAT(header, HasSubstr("property double x\n"));
    EXPECT_THAT(header, HasSubstr("property uchar alpha\n"));

    const LoadedScan read = loadScan(path.string());
    expectSameAttributes(read.cloud, cloud);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 expected = cloud.fileCoordinates(i);
        const glm::dvec3 actual = read.cloud.fileCoordinates(i);
        for (int axis = 0; axis < 3; ++axis) {
            // Double in the file; in memory, floats relative to the centre of a 10 m cloud
            // (half a step at 5 m: 2.4e-7, twice for re-centring).
            EXPECT_NEAR(actual[axis], expected[axis], 1e-6) << "point " << i;
        }
    }
}

TEST(PlyWriterTest, FloatIsChosenWhileItKeepsAMillionthOfTheExtent) {
    // 1 m wide at 10 m from the origin: a float step there is 1e-6, its half 5e-7 of the extent.
    EXPECT_FALSE(needsDoubleCoordinates(everyAttribute({10.0, 0.0, 0.0}, 1.0)));
    // The same at 100 km: a step of 8 mm.
    EXPECT_TRUE(needsDoubleCoordinates(everyAttribute({1e5, 0.0, 0.0}, 1.0)));
}

TEST(PlyWriterTest, DoublesAreChosenWhereFloatLosesTheFilesGrid) {
    // A LAS survey of 1 cm steps, 200 km wide, 850 km east: float rounds by 6 cm there. The old
    // rule, a millionth of the extent (20 cm), took float.
    PointCloud wide = everyAttribute({850000.0, 0.0, 100.0}, 200000.0);
    EXPECT_FALSE(needsDoubleCoordinates(wide));  // without a grid: a millionth, 20 cm
    wide.coordinateStep = 0.01;
    EXPECT_TRUE(needsDoubleCoordinates(wide));
    // 2 km at the origin, on a 1 cm grid: float's 61 microns round back to the same steps.
    PointCloud near = everyAttribute({0.0, 0.0, 0.0}, 2000.0);
    near.coordinateStep = 0.01;
    EXPECT_FALSE(needsDoubleCoordinates(near));
    // The same on a 0.1 mm grid 2 km from the origin: half a step is 50 microns, float's 122.
    PointCloud fine = everyAttribute({2000.0, 0.0, 0.0}, 2000.0);
    fine.coordinateStep = 1e-4;
    EXPECT_TRUE(needsDoubleCoordinates(fine));
    // Doubles from the file, 20 km wide at 500 km: float's 16 mm there, a millionth 2 cm.
    PointCloud doubles = everyAttribute({500000.0, 500000.0, 0.0}, 20000.0);
    EXPECT_FALSE(needsDoubleCoordinates(doubles));
    doubles.doubleCoordinates = true;
    EXPECT_TRUE(needsDoubleCoordinates(doubles));
}

TEST(PlyWriterTest, PositionsOnlyAndNoFaces) {
    const test::TempDir dir;
    PointCloudBuilder builder({}, 2);
    for (const double x : {1.0, 2.0}) {
        PointRecord record;
        record.position = {x, 0.0, 0.0};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const auto path = dir / "plain.ply";
    writePly(path, cloud);
    const std::string header = headerOf(path);
    EXPECT_THAT(header, Not(HasSubstr("red")));
    EXPECT_THAT(header, Not(HasSubstr("face")));
    // Header, then 2 x 3 floats.
    EXPECT_EQ(std::filesystem::file_size(path),
              header.size() + std::string("end_header\n").size() + 2 * 3 * sizeof(float));
    const LoadedScan read = loadScan(path.string());
    EXPECT_EQ(read.cloud.size(), 2u);
    EXPECT_FALSE(read.cloud.hasColors());
}

TEST(PlyWriterTest, UnwritablePathIsAnErrorNamingIt) {
    test::expectUnwritablePathIsAnErrorNamingIt(
        [](const std::filesystem::path& path) {
            writePly(path, everyAttribute({0, 0, 0}, 1.0));
        },
        "out.ply");
}

}  // namespace
}  // namespace subscan
