// OFF meshes: the keyword's variants, vertex colours and normals, polygons fanned into
// triangles, and one sentence for each kind of malformed file.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

/// A unit cube: 8 vertices, 6 quads (each fanned into 2 triangles).
constexpr const char* kCube =
    "OFF\n"
    "# a comment line, then a blank one\n"
    "\n"
    "8 6 12\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
    "0 0 1\n1 0 1\n1 1 1\n0 1 1  # a comment after a vertex\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

TEST(OffReaderTest, CubeIsAMeshOfTwelveTriangles) {
    const LoadedScan scan = test::decode(kCube, "cube.off");
    EXPECT_EQ(scan.format, "off");
    EXPECT_EQ(scan.formatDetail, "OFF (ASCII): 8 vertices, 6 faces");
    ASSERT_EQ(scan.cloud.size(), 8u);
    test::expectPosition(scan.cloud, 6, 1, 1, 1);
    test::expectPosition(scan.cloud, 3, 0, 1, 0);
    ASSERT_EQ(scan.cloud.triangles.size(), 12u);
    // The fan of "4 0 3 2 1": (0 3 2) and (0 2 1).
    EXPECT_EQ(scan.cloud.triangles[0], (Triangle{0, 3, 2}));
    EXPECT_EQ(scan.cloud.triangles[1], (Triangle{0, 2, 1}));
    EXPECT_FALSE(scan.cloud.hasColors());
    EXPECT_FALSE(scan.cloud.hasNormals());
}

TEST(OffReaderTest, VertexColoursAsBytesOrFractions) {
    // Integers are 0..255, numbers with a point 0..1; RGB or RGBA.
    const LoadedScan bytes =
        test::decode("COFF\n3 1 0\n0 0 0 255 128 0 255\n1 0 0 10 20 30\n0 1 0 0 0 0 0\n3 0 1 2\n");
    ASSERT_TRUE(bytes.cloud.hasColors());
    EXPECT_EQ(bytes.cloud.colors[0], (Rgba8{255, 128, 0, 255}));
    EXPECT_EQ(bytes.cloud.colors[1], (Rgba8{10, 20, 30, 255}));
    EXPECT_EQ(bytes.cloud.colors[2], (Rgba8{0, 0, 0, 0}));
    const LoadedScan fractions =
        test::decode("COFF 2 0 0\n0 0 0 1.0 0.5 0.0 1.0\n1 0 0 0.2 1e-1 -0.5\n");
    // 0.5 * 255 = 127.5 rounds to 128; -0.5 is clamped to 0.
    EXPECT_EQ(fractions.cloud.colors[0], (Rgba8{255, 128, 0, 255}));
    EXPECT_EQ(fractions.cloud.colors[1], (Rgba8{51, 26, 0, 255}));
}

TEST(OffReaderTest, ColourScaleIsDecidedOnceForTheWholeFile) {
    // Writers that print with %g write 1.0 as "1": white, red and alpha 1 were read as 0..255
    // (black, transparent) next to vertices with a decimal point.
    const LoadedScan units = test::decode(
        "COFF\n5 0 0\n0 0 0 1 1 1 1\n1 0 0 0.5 0.5 0.5 1\n0 1 0 1 0 0 1\nnan 0 0 0 0 0 0.5\n"
        "0 0 1 0.25 1 0 1\n");
    ASSERT_EQ(units.cloud.size(), 4u);  // the NaN vertex is dropped, its colour with it
    EXPECT_EQ(units.cloud.colors[0], (Rgba8{255, 255, 255, 255}));
    EXPECT_EQ(units.cloud.colors[1], (Rgba8{128, 128, 128, 255}));
    EXPECT_EQ(units.cloud.colors[2], (Rgba8{255, 0, 0, 255}));
    EXPECT_EQ(units.cloud.colors[3], (Rgba8{64, 255, 0, 255}));
    // A value above 1 makes decimals 0..255, as in PLY and text files: "255.0" is not clamped.
    const LoadedScan bytes = test::decode("COFF\n2 0 0\n0 0 0 255.0 128.0 0.0\n1 0 0 0.5 1 1\n");
    EXPECT_EQ(bytes.cloud.colors[0], (Rgba8{255, 128, 0, 255}));
    EXPECT_EQ(bytes.cloud.colors[1], (Rgba8{1, 1, 1, 255}));  // 0.5 rounds half up
}

TEST(OffReaderTest, NormalsHomogeneousCoordinatesAndTextureCoordinates) {
    const LoadedScan normals = test::decode("NOFF\n2 0 0\n0 0 0 0 0 1\n1 2 3 0 1 0\n", "n.off");
    ASSERT_TRUE(normals.cloud.hasNormals());
    EXPECT_EQ(normals.cloud.normals[1], glm::vec3(0, 1, 0));
    // 4OFF divides by w; ST adds two numbers after everything else; C and N together.
    const LoadedScan homogeneous = test::decode("4OFF\n2 0 0\n2 4 6 2\n1 1 1 1\n");
    test::expectPosition(homogeneous.cloud, 0, 1, 2, 3);
    const LoadedScan all =
        test::decode("STCNOFF\n1 0 0\n1 2 3 0 0 1 0.5 0.5 0.5 1 0.25 0.75\n", "all.off");
    test::expectPosition(all.cloud, 0, 1, 2, 3);
    EXPECT_EQ(all.cloud.normals[0], glm::vec3(0, 0, 1));
    EXPECT_EQ(all.cloud.colors[0], (Rgba8{128, 128, 128, 255}));
}

TEST(OffReaderTest, WithoutTheKeywordTheCountsComeFirst) {
    // The keyword is optional: the extension names the format.
    const LoadedScan scan = test::decode("3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "bare.off");
    EXPECT_EQ(scan.format, "off");
    EXPECT_EQ(scan.cloud.triangles.size(), 1u);
}

TEST(OffReaderTest, DegenerateFacesAreSkippedWithAWarning) {
    const LoadedScan scan = test::decode("OFF\n3 3 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n1 2\n3 0 1 2\n");
    EXPECT_EQ(scan.cloud.triangles.size(), 1u);
    EXPECT_THAT(scan.warnings, ::testing::Contains(HasSubstr("skipped 2 faces")));
}

TEST(OffReaderTest, MalformedFilesAreOneSentence) {
    struct Case {
        const char* file;
        const char* message;
    };
    const Case cases[] = {
        {"OFF\n", "the OFF file ends before the vertex and face counts (file truncated?)"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n", "ends before vertex 3 of 3 (file truncated?)"},
        {"OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "ends before face 2 of 2"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
         "line 6: face 1 refers to vertex 3, outside 0..2 (the file has 3 vertices)"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
         "line 6: face 1 names 4 vertices but lists 3"},
        {"OFF\n2 0 0\n0 0 0\n1 zero 0\n", "line 4: the coordinate 'zero' is not a number"},
        {"OFF\n2 0 0\n0 0\n", "line 3: vertex 1 has 2 numbers; OFF vertices have 3"},
        {"COFF\n1 0 0\n0 0 0 1\n", "line 3: vertex 1 has 4 numbers; COFF vertices have 6"},
        {"OFF\n-1 0 0\n", "line 2: the vertex count '-1' is not a count from 0 to"},
        {"OFF\n1.5 0 0\n", "the vertex count '1.5' is not a count"},
        {"OFF\n7\n", "line 2: expected the vertex and face counts, found '7'"},
        {"OFF BINARY\n", "binary OFF files are not supported"},
        {"nOFF\n4\n", "announces vertices of another dimension than 3"},
        {"OFF\n0 0 0\n", "contains no points"},
        // A count the file cannot hold: the end of the file, not an allocation of 4e9 points.
        {"OFF\n4294967294 0 0\n0 0 0\n", "ends before vertex 2 of 4294967294"},
    };
    for (const Case& c : cases) {
        const std::string message = test::decodeError(c.file, "bad.off");
        EXPECT_THAT(message, HasSubstr(c.message)) << c.file;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace subscan
