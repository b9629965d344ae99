#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::appendBytes;
using test::decode;
using test::decodeError;
using test::expectPosition;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

std::string binaryHeader(const char* encoding, const std::string& body) {
    return std::string("ply\nformat ") + encoding + " 1.0\n" + body + "end_header\n";
}

TEST(PlyReaderTest, AsciiPositionsAnyPropertyOrderWithColorNormalIntensity) {
    const std::string file =
        "ply\nformat ascii 1.0\ncomment made by hand\nobj_info scanner 42\n"
        "element vertex 2\n"
        "property float nx\nproperty uchar red\nproperty float z\nproperty float ny\n"
        "property uchar green\nproperty double x\nproperty float nz\nproperty uchar blue\n"
        "property float y\nproperty float intensity\n"
        "end_header\n"
        "0 10 3 1 20 1 0 30 2 0.5\n"
        "1 255 -3.5 0 0 +4.25 0 128 -2e1 7\n";
    const LoadedScan scan = decode(file, "hand.ply");
    EXPECT_EQ(scan.format, "ply");
    EXPECT_EQ(scan.formatDetail, "PLY 1.0 ascii");
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), 2u);
    expectPosition(cloud, 0, 1, 2, 3);
    expectPosition(cloud, 1, 4.25, -20, -3.5);
    ASSERT_TRUE(cloud.hasColors());
    EXPECT_EQ(cloud.colors[0], (Rgba8{10, 20, 30, 255}));
    EXPECT_EQ(cloud.colors[1], (Rgba8{255, 0, 128, 255}));
    ASSERT_TRUE(cloud.hasNormals());
    EXPECT_EQ(cloud.normals[0], glm::vec3(0, 1, 0));
    EXPECT_EQ(cloud.normals[1], glm::vec3(1, 0, 0));
    ASSERT_TRUE(cloud.hasIntensities());
    EXPECT_EQ(cloud.intensities[1], 7.0f);
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(1, -20, -3.5));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(4.25, 2, 3));
    // x is a double: writers keep it one (needsDoubleCoordinates).
    EXPECT_TRUE(cloud.doubleCoordinates);
}

/// Writes the same three points in both binary byte orders with mixed scalar types.
std::string mixedTypesBinary(bool bigEndian) {
    std::string file =
        binaryHeader(bigEndian ? "binary_big_endian" : "binary_little_endian",
                     "element vertex 3\nproperty double x\nproperty int16 y\nproperty float z\n"
                     "property ushort red\nproperty ushort green\nproperty ushort blue\n"
                     "property uint8 alpha\nproperty int8 scalar_intensity\n");
    const double xs[] = {0.125, -1e-3, 1e6};
    const std::int16_t ys[] = {-32768, 0, 32767};
    const float zs[] = {1.5f, -2.25f, 3.0f};
    for (int i = 0; i < 3; ++i) {
        appendBytes(file, xs[i], bigEndian);
        appendBytes(file, ys[i], bigEndian);
        appendBytes(file, zs[i], bigEndian);
        appendBytes(file, std::uint16_t(65535), bigEndian);
        appendBytes(file, std::uint16_t(257 * i), bigEndian);
        appendBytes(file, std::uint16_t(0), bigEndian);
        appendBytes(file, std::uint8_t(100 + i), bigEndian);
        appendBytes(file, std::int8_t(-5 + i), bigEndian);
    }
    return file;
}

TEST(PlyReaderTest, BinaryBothByteOrdersAllScalarTypes) {
    for (const bool bigEndian : {false, true}) {
        SCOPED_TRACE(bigEndian ? "big endian" : "little endian");
        const PointCloud cloud = decode(mixedTypesBinary(bigEndian), "mixed.ply").cloud;
        ASSERT_EQ(cloud.size(), 3u);
        // x spans 1e6, so float steps relative to the centre are 1/32: compare bounds exactly
        // (kept in double) and positions with that resolution.
        EXPECT_EQ(cloud.bounds.min, glm::dvec3(-1e-3, -32768, -2.25));
        EXPECT_EQ(cloud.bounds.max, glm::dvec3(1e6, 32767, 3.0));
        EXPECT_NEAR(cloud.fileCoordinates(2).x, 1e6, 0.04);
        EXPECT_EQ(cloud.fileCoordinates(0).y, -32768.0);
        EXPECT_EQ(cloud.colors[0], (Rgba8{255, 0, 0, 100}));
        EXPECT_EQ(cloud.colors[2], (Rgba8{255, 2, 0, 102}));
        EXPECT_EQ(cloud.intensities[0], -5.0f);
    }
}

TEST(PlyReaderTest, FloatAndDiffuseColours) {
    const std::string file =
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
        "property float z\nproperty float diffuse_red\nproperty float diffuse_green\n"
        "property float diffuse_blue\nend_header\n0 0 0 1.0 0.5 0\n";
    const PointCloud cloud = decode(file, "f.ply").cloud;
    EXPECT_EQ(cloud.colors[0], (Rgba8{255, 128, 0, 255}));
}

/// A binary PLY of one vertex per colour, with colour channels of `type`.
template <class Channel>
std::string colorPly(const char* type, const std::vector<std::array<Channel, 3>>& colors) {
    std::string file = binaryHeader(
        "binary_little_endian",
        fmt::format("element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                    "property {} red\nproperty {} green\nproperty {} blue\n",
                    colors.size(), type, type, type));
    for (std::size_t i = 0; i < colors.size(); ++i) {
        // The second vertex is dropped (NaN), so the colours kept must skip its colour.
        appendBytes(file, i == 1 ? NAN : static_cast<float>(i));
        appendBytes(file, 0.0f);
        appendBytes(file, 0.0f);
        for (const Channel c : colors[i]) {
            appendBytes(file, c);
        }
    }
    return file;
}

TEST(PlyReaderTest, SixteenBitColourIsEightBitUnlessAValueOfTheFileIsLarger) {
    // PDAL writes LAS colour as ushort: 8-bit values there were divided by 257 (black).
    using Word = std::array<std::uint16_t, 3>;
    const PointCloud bytes =
        decode(colorPly<std::uint16_t>("ushort",
                                       {Word{248, 149, 136}, Word{1, 2, 3}, Word{0, 255, 100}}),
               "bytes.ply")
            .cloud;
    ASSERT_EQ(bytes.size(), 2u);
    EXPECT_EQ(bytes.colors[0], (Rgba8{248, 149, 136, 255}));
    EXPECT_EQ(bytes.colors[1], (Rgba8{0, 255, 100, 255}));
    // One value above 255, in the last vertex, makes every vertex 16-bit.
    const PointCloud words =
        decode(colorPly<std::uint16_t>("uint16",
                                       {Word{514, 257, 0}, Word{1, 2, 3}, Word{0, 255, 65535}}),
               "words.ply")
            .cloud;
    ASSERT_EQ(words.size(), 2u);
    EXPECT_EQ(words.colors[0], (Rgba8{2, 1, 0, 255}));
    EXPECT_EQ(words.colors[1], (Rgba8{0, 1, 255, 255}));
}

TEST(PlyReaderTest, ColourBeyondEightBitsIsMarkedCut) {
    // convert warns of it as of LAS colour; it cut 16-bit PLY colour to 8 bits without a word.
    using Word = std::array<std::uint16_t, 3>;
    const auto cut = [](const std::string& file) {
        return decode(file, "colour.ply").cloud.colorCutTo8Bits;
    };
    EXPECT_TRUE(cut(colorPly<std::uint16_t>("ushort", {Word{1000, 0, 0}})));
    // 8-bit values, or 16-bit ones that are 8-bit values times 257, lose nothing.
    EXPECT_FALSE(cut(colorPly<std::uint16_t>("ushort", {Word{255, 3, 0}})));
    EXPECT_FALSE(cut(colorPly<std::uint16_t>("ushort", {Word{65535, 514, 0}})));
    // colorPly drops the second vertex (NaN): its colour is not written.
    EXPECT_FALSE(cut(colorPly<std::uint16_t>("ushort", {Word{65535, 0, 0}, Word{1, 2, 3}})));
    // 32-bit colour over 255 is clamped.
    using Wide = std::array<std::uint32_t, 3>;
    EXPECT_TRUE(cut(colorPly<std::uint32_t>("uint", {Wide{0, 300, 0}})));
    EXPECT_FALSE(cut(colorPly<std::uint32_t>("uint", {Wide{0, 255, 0}})));
}

TEST(PlyReaderTest, FloatColourIsZeroToOneUnlessAValueOfTheFileIsLarger) {
    using Floats = std::array<float, 3>;
    // (255, 128, 0) was clamped to (255, 255, 0).
    const PointCloud bytes =
        decode(colorPly<float>("float", {Floats{1.0f, 0.5f, 0.0f}, Floats{9.0f, 9.0f, 9.0f},
                                         Floats{255.0f, 128.0f, 0.0f}}),
               "bytes.ply")
            .cloud;
    ASSERT_EQ(bytes.size(), 2u);
    EXPECT_EQ(bytes.colors[0], (Rgba8{1, 1, 0, 255}));  // 0.5 rounds half up
    EXPECT_EQ(bytes.colors[1], (Rgba8{255, 128, 0, 255}));
    const PointCloud units =
        decode(colorPly<float>("float32", {Floats{1.0f, 0.5f, 0.0f}, Floats{0.0f, 0.0f, 0.0f},
                                           Floats{0.25f, 1.0f, 0.0f}}),
               "units.ply")
            .cloud;
    ASSERT_EQ(units.size(), 2u);
    EXPECT_EQ(units.colors[0], (Rgba8{255, 128, 0, 255}));
    EXPECT_EQ(units.colors[1], (Rgba8{64, 255, 0, 255}));
}

TEST(PlyReaderTest, FacesAreFannedIntoTriangles) {
    const std::string file =
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 2\n3 0 1 2\n5 0 1 2 3 4\n";
    const PointCloud cloud = decode(file, "mesh.ply").cloud;
    ASSERT_EQ(cloud.triangles.size(), 4u);
    EXPECT_EQ(cloud.triangles[0], (Triangle{0, 1, 2}));
    EXPECT_EQ(cloud.triangles[1], (Triangle{0, 1, 2}));
    EXPECT_EQ(cloud.triangles[2], (Triangle{0, 2, 3}));
    EXPECT_EQ(cloud.triangles[3], (Triangle{0, 3, 4}));
}

TEST(PlyReaderTest, BinaryFacesWithVertexIndexNameAndOtherElementsSkipped) {
    for (const bool bigEndian : {false, true}) {
        SCOPED_TRACE(bigEndian ? "big endian" : "little endian");
        std::string file = binaryHeader(
            bigEndian ? "binary_big_endian" : "binary_little_endian",
            "element camera 1\nproperty float fov\nproperty list uchar float extra\n"
            "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "property list uchar float unused_list\n"
            "element range_grid 4\nproperty list uchar int vertex_indices\n"
            "element face 1\nproperty uchar flags\nproperty list uint8 uint32 vertex_index\n");
        appendBytes(file, 60.0f, bigEndian);
        appendBytes(file, std::uint8_t(2), bigEndian);
        appendBytes(file, 1.0f, bigEndian);
        appendBytes(file, 2.0f, bigEndian);
        for (int i = 0; i < 3; ++i) {
            appendBytes(file, float(i), bigEndian);
            appendBytes(file, 0.0f, bigEndian);
            appendBytes(file, 0.0f, bigEndian);
            appendBytes(file, std::uint8_t(i), bigEndian);  // i floats of unused_list
            for (int k = 0; k < i; ++k) {
                appendBytes(file, 9.0f, bigEndian);
            }
        }
        for (int i = 0; i < 4; ++i) {  // range_grid: 0 or 1 index per cell
            appendBytes(file, std::uint8_t(i % 2), bigEndian);
            if (i % 2) {
                appendBytes(file, std::int32_t(i), bigEndian);
            }
        }
        appendBytes(file, std::uint8_t(7), bigEndian);
        appendBytes(file, std::uint8_t(3), bigEndian);
        for (std::uint32_t v : {2u, 1u, 0u}) {
            appendBytes(file, v, bigEndian);
        }
        const PointCloud cloud = decode(file, "grid.ply").cloud;
        ASSERT_EQ(cloud.size(), 3u);
        expectPosition(cloud, 2, 2, 0, 0);
        ASSERT_EQ(cloud.triangles.size(), 1u);
        EXPECT_EQ(cloud.triangles[0], (Triangle{2, 1, 0}));
    }
}

TEST(PlyReaderTest, StrayByeLinesAndCrLfHeaderAreTolerated) {
    const std::string file =
        "ply\r\nformat ascii 1.0\r\nbye\r\nelement vertex 1\r\nproperty float x\r\n"
        "property float y\r\nproperty float z\r\nbye\r\nend_header\r\n1 2 3\r\n";
    const PointCloud cloud = decode(file, "bye.ply").cloud;
    ASSERT_EQ(cloud.size(), 1u);
    expectPosition(cloud, 0, 1, 2, 3);
}

TEST(PlyReaderTest, AsciiItemsAreLinesWhateverTheirBlanksAndLineEnds) {
    // Blank lines, tabs, trailing blanks and CRLF; lists in an element before the vertices and
    // in one after the faces, which is read (and checked) to the end of the body.
    const std::string file =
        "ply\nformat ascii 1.0\nelement camera 1\nproperty list uchar float k\n"
        "property float f\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "element edge 1\nproperty int a\nproperty list uchar int b\nend_header\n"
        "2 0.5 0.5 35\r\n\r\n0 0 0  \r\n\t1 0 0\t\n\n  0 1 0\n3 0 1 2\r\n7 0\n\n  \n";
    const LoadedScan scan = decode(file, "blanks.ply");
    ASSERT_EQ(scan.cloud.size(), 3u);
    expectPosition(scan.cloud, 1, 1, 0, 0);
    expectPosition(scan.cloud, 2, 0, 1, 0);
    ASSERT_EQ(scan.cloud.triangles.size(), 1u);
    EXPECT_THAT(scan.warnings, IsEmpty());
}

TEST(PlyReaderTest, AsciiLineWithTheWrongNumberOfValuesNamesTheLine) {
    const std::string xyz =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\n";
    const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    const Case cases[] = {
        // An undeclared column shifted every value after it: (0,0,0) (7,1,1) (1,7,2)...
        {"extra column", xyz + "end_header\n0 0 0 7\n1 1 1 7\n2 2 2 7\n3 3 3 7\n",
         "PLY line 8 has 4 values, but the header's properties of vertex 1 need 3"},
        {"missing value", xyz + "end_header\n0 0 0\n1 1\n2 2 2\n3 3 3\n0 0 0\n",
         "PLY line 9 has 2 values, but the header's properties of vertex 2 need 3"},
        {"short face", xyz + faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1\n",
         "PLY line 14 has 3 values, but the header's properties of face 1 need 4"},
        // Vertex lines read as faces gave "skipped 1 PLY faces with fewer than 3 vertices".
        {"vertex count too small",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\n" +
             faces + "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n",
         "PLY line 13 has 3 values, but the header's properties of face 1 need 2"},
        {"list count missing",
         "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
         "property float z\nproperty list uchar float extra\nproperty float w\nend_header\n"
         "0 0 0\n",
         "PLY line 10 has 3 values, but the header's properties of vertex 1 need at least 5"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_THAT(decodeError(c.file, "lines.ply"), HasSubstr(c.expected));
    }
}

TEST(PlyReaderTest, AsciiLinesAfterTheLastElementAreIgnoredWithAWarning) {
    // The header says 2 vertices, the body holds 4: the last 2 were ignored silently.
    const std::string file =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 1 1\n2 2 2\n\n3 3 3\n";
    const LoadedScan scan = decode(file, "more.ply");
    EXPECT_EQ(scan.cloud.size(), 2u);
    EXPECT_THAT(scan.warnings, ::testing::Contains(HasSubstr(
                                   "ignored the 2 PLY ascii lines after the last "
                                   "element, the 2 vertex items declared in the header")));
}

TEST(PlyReaderTest, NanVerticesAreDroppedAndFacesRemapped) {
    const std::string file =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\nnan 0 0\n1 0 0\n0 1 inf\n3 0 2 2\n3 0 1 2\n";
    const LoadedScan scan = decode(file, "nan.ply");
    ASSERT_EQ(scan.cloud.size(), 2u);
    ASSERT_EQ(scan.cloud.triangles.size(), 1u);
    EXPECT_EQ(scan.cloud.triangles[0], (Triangle{0, 1, 1}));
    EXPECT_THAT(scan.warnings, ::testing::Contains(HasSubstr("dropped 2 of 4 points")));
}

TEST(PlyReaderTest, BadInputsGiveOneClearSentence) {
    const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    std::string truncatedBinary = binaryHeader("binary_little_endian", "element vertex 3\n" + xyz);
    for (int i = 0; i < 7; ++i) {  // 2 vertices and a third of one
        appendBytes(truncatedBinary, 1.0f);
    }
    const Case cases[] = {
        {"no magic", "plx\nformat ascii 1.0\n", "PLY magic"},
        {"no end_header", "ply\nformat ascii 1.0\nelement vertex 1\n", "no 'end_header'"},
        {"no format", "ply\nelement vertex 1\n" + xyz + "end_header\n1 2 3\n", "no 'format'"},
        {"unknown encoding", "ply\nformat binary_middle_endian 1.0\nend_header\n",
         "unknown encoding"},
        {"unknown type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n",
         "unknown property type"},
        {"list position",
         "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float x\n"
         "property float y\nproperty float z\nend_header\n1 1 2 3\n",
         "'x' is declared as a list"},
        {"missing z",
         "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float "
         "y\nend_header\n1 2\n",
         "no 'z' property"},
        {"no vertex element", "ply\nformat ascii 1.0\nelement face 0\nend_header\n",
         "no 'vertex' element"},
        {"truncated ascii",
         "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "end_header\n1 2 3\n4 5 6\n7 8",
         "ends inside vertex 3 of 3"},
        {"truncated binary", truncatedBinary, "ends inside vertex 3 of 3"},
        {"count larger than body",
         binaryHeader("binary_little_endian", "element vertex 1000000000000\n" + xyz),
         "more than the"},
        {"non-numeric", "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz + "end_header\n1 two 3\n",
         "non-numeric value 'two'"},
        // Clamped to 255 or rounded to 2 before: a text file can say what a binary one cannot.
        {"colour beyond uchar",
         "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
             "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
             "1 2 3 300 0 0\n",
         "vertex 1 has red = 300, which its integer type cannot hold"},
        {"fraction in an integer",
         "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
             "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
             "1 2 3 0 1.7 0\n",
         "green = 1.7"},
        {"alpha beyond uchar",
         "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
             "property uchar red\nproperty uchar green\nproperty uchar blue\n"
             "property uchar alpha\nend_header\n1 2 3 4 5 6 -1\n",
         "alpha = -1"},
        {"face index out of range",
         "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
         "vertex index outside 0..2"},
        {"negative face index",
         "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
         "vertex index outside"},
        {"zero points", "ply\nformat ascii 1.0\nelement vertex 0\n" + xyz + "end_header\n",
         "contains no points"},
        {"all NaN",
         "ply\nformat ascii 1.0\nelement vertex 2\n" + xyz + "end_header\nnan 0 0\n0 inf 0\n",
         "all 2 points have NaN"},
        {"bad element count", "ply\nformat ascii 1.0\nelement vertex -4\n",
         "not a non-negative integer"},
        {"negative list length",
         "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n-3 0\n",
         "invalid list length"},
        {"huge list length",  // found by the fuzzer: 3.7e78 as a list count
         "ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n"
             "3666666666666666666666666666666666666666666666666666666666666666666666666666666 0\n",
         "invalid list length"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_THAT(decodeError(c.file, "bad.ply"), HasSubstr(c.expected));
    }
}

TEST(PlyReaderTest, ValuesThatAreNotReadAreNotJudged) {
    // An integer property subscan does not read, and an element it skips, may hold anything
    // a text file writes; only the colour channels read are checked against their type.
    const std::string file =
        "ply\nformat ascii 1.0\nelement material 1\nproperty uchar id\n"
        "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
        "property uchar quality\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nend_header\n256\n1 2 3 0.5 255.0 -0 7\n";
    const PointCloud cloud = decode(file, "kept.ply").cloud;
    ASSERT_EQ(cloud.size(), 1u);
    EXPECT_EQ(cloud.colors[0].r, 255);
    EXPECT_EQ(cloud.colors[0].g, 0);
    EXPECT_EQ(cloud.colors[0].b, 7);
}

TEST(PlyReaderTest, HugeVertexCountInAsciiDoesNotAllocateOrHang) {
    // A lying count must end at the body's end, not reserve memory for 4 billion points.
    const std::string file =
        "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n1 2 3\n";
    EXPECT_THAT(decodeError(file, "huge.ply"), HasSubstr("ends inside vertex 2 of 4000000000"));
}

}  // namespace
}  // namespace subscan
