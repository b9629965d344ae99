#include <algorithm>
#include <bit>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
// subscan_core links liblzf privately, so its include directory does not reach the tests.
#include <lzf.h>

#include "io/PcdReader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::appendBytes;
using test::decode;
using test::decodeError;
using ::testing::Contains;
using ::testing::HasSubstr;

/// A header in PCL's order; `fieldLines` holds FIELDS, SIZE, TYPE and COUNT.
std::string pcdHeader(const std::string& fieldLines, std::uint64_t width, std::uint64_t height,
                      const std::string& data) {
    return fmt::format(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n{}WIDTH {}\nHEIGHT {}\n"
        "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {}\n",
        fieldLines, width, height, width * height, data);
}

const std::string kFloatXyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

/// The 8-byte size header and LZF stream of binary_compressed data.
std::string compressedBlock(const std::string& uncompressed) {
    std::string compressed(uncompressed.size() + uncompressed.size() / 16 + 64, '\0');
    const unsigned int size =
        lzf_compress(uncompressed.data(), static_cast<unsigned int>(uncompressed.size()),
                     compressed.data(), static_cast<unsigned int>(compressed.size()));
    EXPECT_GT(size, 0u) << "lzf_compress failed";
    std::string block;
    appendBytes(block, static_cast<std::uint32_t>(size));
    appendBytes(block, static_cast<std::uint32_t>(uncompressed.size()));
    return block + compressed.substr(0, size);
}

/// An LZF stream of literal runs only: a run is its length - 1 (0..31), then its bytes.
std::string lzfLiterals(const std::string& bytes) {
    std::string stream;
    for (std::size_t i = 0; i < bytes.size(); i += 32) {
        const std::string run = bytes.substr(i, 32);
        stream += static_cast<char>(run.size() - 1);
        stream += run;
    }
    return stream;
}

std::string sizeHeader(std::uint32_t compressed, std::uint32_t uncompressed) {
    std::string block;
    appendBytes(block, compressed);
    appendBytes(block, uncompressed);
    return block;
}

/// One point with every attribute the reader keeps.
struct SamplePoint {
    double x, y, z;
    std::uint32_t colorBits;  // 0xAARRGGBB
    float normal[3];
    std::uint16_t intensity;
};

// UTM-sized x and y: double fields must keep all their digits in the bounds.
const std::vector<SamplePoint> kSamplePoints = {
    {500000.125, 5400000.0625, 1.5, 0x10203040u, {0, 0, 1}, 7},
    {500001.875, 5400002.5, -2.25, 0x80FF0080u, {1, 0, 0}, 65535},
    {499999.0, 5399999.75, 0.0, 0xFF000000u, {0, -1, 0}, 0},
};

/// Field lines for the sample layout: padding and a COUNT > 1 descriptor between the fields we
/// keep, and `colorName` ("rgb" or "rgba") of TYPE `colorType`.
std::string sampleFieldLines(const std::string& colorName, char colorType) {
    return fmt::format(
        "FIELDS x _ y z {} fpfh normal_x normal_y normal_z intensity\n"
        "SIZE 8 1 8 8 4 4 4 4 4 2\nTYPE F U F F {} F F F F U\nCOUNT 1 3 1 1 1 33 1 1 1 1\n",
        colorName, colorType);
}

/// Bytes of one field per point in the sample layout, in field order.
std::vector<std::string> sampleColumns() {
    std::vector<std::string> columns(10);
    for (const SamplePoint& p : kSamplePoints) {
        appendBytes(columns[0], p.x);
        columns[1] += std::string("\x7f\x7f\x7f", 3);  // padding: any bytes
        appendBytes(columns[2], p.y);
        appendBytes(columns[3], p.z);
        appendBytes(columns[4], p.colorBits);
        for (int k = 0; k < 33; ++k) {
            appendBytes(columns[5], 99.0f);
        }
        for (int axis = 0; axis < 3; ++axis) {
            appendBytes(columns[6 + axis], p.normal[axis]);
        }
        appendBytes(columns[9], p.intensity);
    }
    return columns;
}

std::string sampleBinary(const std::string& colorName, char colorType) {
    const std::vector<std::string> columns = sampleColumns();
    std::string file =
        pcdHeader(sampleFieldLines(colorName, colorType), kSamplePoints.size(), 1, "binary");
    for (std::size_t i = 0; i < kSamplePoints.size(); ++i) {
        for (const std::string& column : columns) {
            const std::size_t fieldBytes = column.size() / kSamplePoints.size();
            file += column.substr(i * fieldBytes, fieldBytes);
        }
    }
    return file;
}

std::string sampleCompressed(const std::string& colorName, char colorType) {
    std::string uncompressed;
    for (const std::string& column : sampleColumns()) {
        uncompressed += column;
    }
    return pcdHeader(sampleFieldLines(colorName, colorType), kSamplePoints.size(), 1,
                     "binary_compressed") +
           compressedBlock(uncompressed);
}

/// Shortest text that reads back as exactly `value`.
template <class T>
std::string exactText(T value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
}

/// rgb in ascii: `asFloat` writes the float whose bits are the colour (older PCL), otherwise
/// the integer value of the bits (PCL since 1.7).
std::string sampleAscii(const std::string& colorName, bool asFloat) {
    std::string file =
        pcdHeader(sampleFieldLines(colorName, 'F'), kSamplePoints.size(), 1, "ascii");
    for (const SamplePoint& p : kSamplePoints) {
        file += fmt::format("{} 1 2 3 {} {} ", exactText(p.x), exactText(p.y), exactText(p.z));
        file +=
            asFloat ? exactText(std::bit_cast<float>(p.colorBits)) : std::to_string(p.colorBits);
        for (int k = 0; k < 33; ++k) {
            file += " 99";
        }
        file += fmt::format(" {} {} {} {}\n", p.normal[0], p.normal[1], p.normal[2], p.intensity);
    }
    return file;
}

void expectSamplePoints(const LoadedScan& scan, bool alphaFromFile) {
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), kSamplePoints.size());
    ASSERT_TRUE(cloud.hasColors());
    ASSERT_TRUE(cloud.hasNormals());
    ASSERT_TRUE(cloud.hasIntensities());
    for (std::size_t i = 0; i < kSamplePoints.size(); ++i) {
        SCOPED_TRACE(i);
        const SamplePoint& p = kSamplePoints[i];
        const glm::dvec3 position = cloud.fileCoordinates(i);
        // Positions are floats relative to the centre of a cloud under 4 units wide: float
        // steps there are at most 2.4e-7.
        EXPECT_NEAR(position.x, p.x, 1e-6);
        EXPECT_NEAR(position.y, p.y, 1e-6);
        EXPECT_NEAR(position.z, p.z, 1e-6);
        const std::uint32_t bits = p.colorBits;
        EXPECT_EQ(
            cloud.colors[i],
            (Rgba8{static_cast<std::uint8_t>(bits >> 16), static_cast<std::uint8_t>(bits >> 8),
                   static_cast<std::uint8_t>(bits),
                   alphaFromFile ? static_cast<std::uint8_t>(bits >> 24) : std::uint8_t{255}}));
        EXPECT_EQ(cloud.normals[i], glm::vec3(p.normal[0], p.normal[1], p.normal[2]));
        EXPECT_EQ(cloud.intensities[i], static_cast<float>(p.intensity));
    }
    // Bounds are kept in double: exact.
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(499999.0, 5399999.75, -2.25));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(500001.875, 5400002.5, 1.5));
    EXPECT_TRUE(cloud.doubleCoordinates);  // SIZE 8, TYPE F
    EXPECT_TRUE(scan.warnings.empty()) << scan.warnings.front();
}

TEST(PcdReaderTest, AsciiRoundTripWithIntegerAndFloatRgb) {
    for (const bool asFloat : {false, true}) {
        SCOPED_TRACE(asFloat ? "rgb written as float" : "rgb written as integer");
        const LoadedScan scan = decode(sampleAscii("rgb", asFloat), "sample.pcd");
        EXPECT_EQ(scan.format, "pcd");
        EXPECT_EQ(scan.formatDetail, "PCD 0.7 ascii, unorganised");
        expectSamplePoints(scan, false);
    }
}

TEST(PcdReaderTest, BinaryRoundTripSkipsPaddingAndMultiValueFields) {
    const LoadedScan scan = decode(sampleBinary("rgb", 'F'), "sample.pcd");
    EXPECT_EQ(scan.formatDetail, "PCD 0.7 binary, unorganised");
    expectSamplePoints(scan, false);
}

TEST(PcdReaderTest, BinaryCompressedRoundTripIsColumnMajor) {
    const LoadedScan scan = decode(sampleCompressed("rgba", 'U'), "sample.pcd");
    EXPECT_EQ(scan.formatDetail, "PCD 0.7 binary_compressed, unorganised");
    expectSamplePoints(scan, true);
}

TEST(PcdReaderTest, PackedColourTypesAndAlpha) {
    // rgb drops the alpha byte whatever the TYPE; rgba keeps it.
    struct Case {
        const char* name;
        char type;
        bool alpha;
    };
    for (const Case& c :
         {Case{"rgb", 'F', false}, Case{"rgb", 'U', false}, Case{"rgb", 'I', false},
          Case{"rgba", 'U', true}, Case{"rgba", 'F', true}, Case{"rgba", 'I', true}}) {
        SCOPED_TRACE(fmt::format("{} {}", c.name, c.type));
        for (const bool compressed : {false, true}) {
            const LoadedScan scan =
                decode(compressed ? sampleCompressed(c.name, c.type) : sampleBinary(c.name, c.type),
                       "colour.pcd");
            expectSamplePoints(scan, c.alpha);
        }
    }
}

TEST(PcdReaderTest, AsciiIntegerColourTypes) {
    const std::string file =
        pcdHeader("FIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F I\nCOUNT 1 1 1 1\n", 2, 1, "ascii") +
        "0 0 0 -16777216\n1 1 1 2130706687\n";
    const PointCloud cloud = decode(file, "int.pcd").cloud;
    ASSERT_EQ(cloud.size(), 2u);
    EXPECT_EQ(cloud.colors[0], (Rgba8{0, 0, 0, 255}));    // 0xFF000000
    EXPECT_EQ(cloud.colors[1], (Rgba8{0, 0, 255, 127}));  // 0x7F0000FF
}

TEST(PcdReaderTest, OrganisedCloudIsFlattenedAndNanPointsDropped) {
    // 4x3 grid; points 1, 2, 5, 10 and 11 have no measurement (NaN in x, y or z).
    std::string xs, ys, zs;
    const std::vector<bool> missing = {false, true,  true,  false, false, true,
                                       false, false, false, false, true,  true};
    for (std::size_t i = 0; i < missing.size(); ++i) {
        const float value = static_cast<float>(i);
        const float nan = std::numeric_limits<float>::quiet_NaN();
        appendBytes(xs, missing[i] && i % 3 == 0 ? nan : value);
        appendBytes(ys, missing[i] && i % 3 == 1 ? nan : -value);
        appendBytes(zs, missing[i] && i % 3 == 2 ? nan : 2 * value);
    }
    const std::string file =
        pcdHeader(kFloatXyz, 4, 3, "binary_compressed") + compressedBlock(xs + ys + zs);
    const LoadedScan scan = decode(file, "grid.pcd");
    EXPECT_EQ(scan.formatDetail, "PCD 0.7 binary_compressed, organised 4x3");
    ASSERT_EQ(scan.cloud.size(), 7u);
    // Row by row, the kept points in file order: 0 3 4 6 7 8 9.
    const std::vector<double> kept = {0, 3, 4, 6, 7, 8, 9};
    for (std::size_t i = 0; i < kept.size(); ++i) {
        // Small integers in a cloud 27 units wide: float steps are 2e-6 at most.
        EXPECT_NEAR(scan.cloud.fileCoordinates(i).x, kept[i], 1e-5);
        EXPECT_NEAR(scan.cloud.fileCoordinates(i).z, 2 * kept[i], 1e-5);
    }
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("dropped 5 of 12 points")));
    // The grid and each kept point's cell, for the sensor view's camera fit.
    EXPECT_EQ(scan.grid.width, 4);
    EXPECT_EQ(scan.grid.height, 3);
    EXPECT_EQ(scan.grid.cellOfPoint, (std::vector<std::uint32_t>{0, 3, 4, 6, 7, 8, 9}));
}

TEST(PcdReaderTest, ViewpointGivesTheSensorPosition) {
    std::string header = pcdHeader(kFloatXyz, 2, 1, "ascii");
    const std::string points = "1 2 3\n4 5 6\n";
    header.replace(header.find("VIEWPOINT 0 0 0 1 0 0 0"), 23,
                   "VIEWPOINT 512000.25 -7.5 1e2 0 1 0 0");
    const LoadedScan scan = decode(header + points, "station.pcd");
    ASSERT_TRUE(scan.sensor.has_value());
    EXPECT_EQ(scan.sensor->position, glm::dvec3(512000.25, -7.5, 100.0));
    EXPECT_THAT(scan.sensor->source, HasSubstr("VIEWPOINT"));
    EXPECT_TRUE(scan.grid.empty());  // HEIGHT 1: unorganised

    // Without the line, PCD's default: the origin.
    std::string noViewpoint = pcdHeader(kFloatXyz, 2, 1, "ascii");
    noViewpoint.erase(noViewpoint.find("VIEWPOINT"), 24);
    const LoadedScan plain = decode(noViewpoint + points, "plain.pcd");
    ASSERT_TRUE(plain.sensor.has_value());
    EXPECT_EQ(plain.sensor->position, glm::dvec3(0.0));
    EXPECT_THAT(plain.sensor->source, HasSubstr("default"));

    for (const char* bad :
         {"VIEWPOINT 0 0 0 1 0 0", "VIEWPOINT 0 0 nan 1 0 0 0", "VIEWPOINT 0 0 0 1 0 0 x"}) {
        std::string broken = pcdHeader(kFloatXyz, 2, 1, "ascii");
        broken.replace(broken.find("VIEWPOINT 0 0 0 1 0 0 0"), 23, bad);
        EXPECT_THAT(decodeError(broken + points),
                    HasSubstr("should read 'VIEWPOINT tx ty tz qw qx qy qz'"))
            << bad;
    }
}

TEST(PcdReaderTest, OldHeaderVariants) {
    struct Case {
        const char* name;
        std::string file;
        const char* detail;
    };
    const Case cases[] = {
        {"PCD .5 without POINTS: WIDTH x HEIGHT",
         "# .PCD v.5 - Point Cloud Data file format\nVERSION .5\nFIELDS x y z\nSIZE 4 4 4\n"
         "TYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nDATA ascii\n1 2 3\n4 5 6\n",
         "PCD 0.5 ascii, unorganised"},
        {"no COUNT, no VIEWPOINT",
         "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 2\n"
         "DATA ascii\n1 2 3\n4 5 6\n",
         "PCD 0.7 ascii, unorganised"},
        {"only POINTS, COLUMNS, no SIZE or TYPE (floats)",
         "COLUMNS x y z\nPOINTS 2\nDATA ascii\n1 2 3\n4 5 6\n", "PCD ascii, unorganised"},
        {"CRLF, comments, blank lines and nan",
         "# comment\r\n\r\nVERSION 0.7\r\nFIELDS x y z\r\nSIZE 4 4 4\r\nTYPE F F F\r\n"
         "COUNT 1 1 1\r\nWIDTH 3\r\nHEIGHT 1\r\nPOINTS 3\r\nDATA ascii\r\n"
         "1 2 3\r\n\r\nnan nan nan\r\n  4\t5 6  \r\n",
         "PCD 0.7 ascii, unorganised"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const LoadedScan scan = decode(c.file, "old.pcd");
        EXPECT_EQ(scan.formatDetail, c.detail);
        ASSERT_EQ(scan.cloud.size(), 2u);
        EXPECT_EQ(scan.cloud.bounds.min, glm::dvec3(1, 2, 3));
        EXPECT_EQ(scan.cloud.bounds.max, glm::dvec3(4, 5, 6));
    }
    const std::string binaryWithoutSizes = "FIELDS x y z\nPOINTS 1\nDATA binary\n";
    std::string file = binaryWithoutSizes;
    for (const float value : {1.0f, 2.0f, 3.0f}) {
        appendBytes(file, value);
    }
    EXPECT_EQ(decode(file, "old.pcd").cloud.bounds.max, glm::dvec3(1, 2, 3));
}

TEST(PcdReaderTest, PdalUpperCaseNamesAndSeparateColourChannels) {
    // PDAL writes X Y Z and 16-bit Red Green Blue holding either 0..255 or 0..65535.
    const std::string fields =
        "FIELDS X Y Z Intensity Red Green Blue\nSIZE 8 8 8 2 2 2 2\nTYPE F F F U U U U\n"
        "COUNT 1 1 1 1 1 1 1\n";
    auto file = [&](std::uint16_t scale) {
        std::string bytes = pcdHeader(fields, 2, 1, "binary");
        for (int i = 0; i < 2; ++i) {
            appendBytes(bytes, 494428.61 + i);
            appendBytes(bytes, 4877455.58);
            appendBytes(bytes, 131.57);
            appendBytes(bytes, std::uint16_t(143));
            appendBytes(bytes, std::uint16_t((68 + i) * scale));
            appendBytes(bytes, std::uint16_t(255 * scale));
            appendBytes(bytes, std::uint16_t(0));
        }
        return bytes;
    };
    const PointCloud eightBit = decode(file(1), "pdal.pcd").cloud;
    ASSERT_EQ(eightBit.size(), 2u);
    EXPECT_EQ(eightBit.bounds.min, glm::dvec3(494428.61, 4877455.58, 131.57));
    EXPECT_EQ(eightBit.colors[0], (Rgba8{68, 255, 0, 255}));
    EXPECT_EQ(eightBit.colors[1], (Rgba8{69, 255, 0, 255}));
    EXPECT_EQ(eightBit.intensities[0], 143.0f);

    const PointCloud sixteenBit = decode(file(257), "pdal16.pcd").cloud;
    EXPECT_EQ(sixteenBit.colors[0], (Rgba8{68, 255, 0, 255}));
    EXPECT_EQ(sixteenBit.colors[1], (Rgba8{69, 255, 0, 255}));

    const std::string byteFields =
        "FIELDS x y z red green blue alpha\nSIZE 4 4 4 1 1 1 1\nTYPE F F F U U U U\n"
        "COUNT 1 1 1 1 1 1 1\n";
    const std::string byteChannels =
        pcdHeader(byteFields, 2, 1, "ascii") + "nan 0 0 1 2 3 4\n0 0 0 10 20 30 40\n";
    const LoadedScan scan = decode(byteChannels, "bytes.pcd");
    ASSERT_EQ(scan.cloud.size(), 1u);
    EXPECT_EQ(scan.cloud.colors[0], (Rgba8{10, 20, 30, 40}));
}

TEST(PcdReaderTest, ColourBeyondEightBitsIsMarkedCut) {
    // convert warns of it as of LAS colour; it cut PDAL's 16-bit PCD colour to 8 bits without a
    // word.
    const auto cut = [](const std::string& sizeAndType, const std::vector<std::string>& points) {
        std::string lines;
        for (const std::string& point : points) {
            lines += point + "\n";
        }
        const std::string fields =
            "FIELDS x y z red green blue\n" + sizeAndType + "COUNT 1 1 1 1 1 1\n";
        return decode(pcdHeader(fields, points.size(), 1, "ascii") + lines, "colour.pcd")
            .cloud.colorCutTo8Bits;
    };
    const std::string words = "SIZE 4 4 4 2 2 2\nTYPE F F F U U U\n";
    EXPECT_TRUE(cut(words, {"0 0 0 1000 0 0"}));
    // 8-bit values, or 16-bit ones that are 8-bit values times 257, lose nothing.
    EXPECT_FALSE(cut(words, {"0 0 0 255 3 0"}));
    EXPECT_FALSE(cut(words, {"0 0 0 65535 514 0"}));
    // The first point is dropped (NaN): its colour is not kept.
    EXPECT_FALSE(cut(words, {"nan 0 0 1000 0 0", "0 0 0 65535 0 0"}));
    // 32-bit channels read as 16-bit: a value over 65535 is clamped, though it is 300 times 257.
    EXPECT_TRUE(cut("SIZE 4 4 4 4 4 4\nTYPE F F F U U U\n", {"0 0 0 77100 0 0"}));
    EXPECT_FALSE(cut("SIZE 4 4 4 1 1 1\nTYPE F F F U U U\n", {"0 0 0 255 3 0"}));
}

TEST(PcdReaderTest, CompressedPclLayoutWithoutPaddingColumns) {
    // PCL's writer leaves '_' fields out of the compressed columns; both layouts are read.
    const std::string fields = "FIELDS x _ y z\nSIZE 4 1 4 4\nTYPE F U F F\nCOUNT 1 4 1 1\n";
    std::string withoutPadding;
    std::string withPadding;
    for (const float value : {1.0f, 2.0f}) {
        appendBytes(withoutPadding, value);
        appendBytes(withPadding, value);
    }
    withPadding += std::string(8, '\x55');
    for (const float value : {3.0f, 4.0f, 5.0f, 6.0f}) {
        appendBytes(withoutPadding, value);
        appendBytes(withPadding, value);
    }
    for (const std::string& columns : {withoutPadding, withPadding}) {
        const PointCloud cloud =
            decode(pcdHeader(fields, 2, 1, "binary_compressed") + compressedBlock(columns),
                   "pad.pcd")
                .cloud;
        EXPECT_EQ(cloud.bounds.min, glm::dvec3(1, 3, 5));
        EXPECT_EQ(cloud.bounds.max, glm::dvec3(2, 4, 6));
    }
}

TEST(PcdReaderTest, AttributesThatCannotBeUsedAreIgnoredWithAWarning) {
    const std::string file =
        pcdHeader("FIELDS x y z rgb intensity\nSIZE 4 4 4 1 4\nTYPE F F F U F\nCOUNT 1 1 1 3 2\n",
                  1, 1, "ascii") +
        "1 2 3 4 5 6 7 8\n";
    const LoadedScan scan = decode(file, "odd.pcd");
    ASSERT_EQ(scan.cloud.size(), 1u);
    EXPECT_FALSE(scan.cloud.hasColors());
    EXPECT_FALSE(scan.cloud.hasIntensities());
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("'rgb': it has COUNT 3")));
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("'intensity': it has COUNT 2")));
}

TEST(PcdReaderTest, AsciiLinesAfterTheDeclaredPointsAreIgnoredWithAWarning) {
    const std::string file = pcdHeader(kFloatXyz, 1, 1, "ascii") + "1 2 3 extra ignored\n4 5 6\n";
    const LoadedScan scan = decode(file, "extra.pcd");
    ASSERT_EQ(scan.cloud.size(), 1u);
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("ignored the PCD ascii lines after the 1")));
}

TEST(PcdReaderTest, ProgressIsReportedWhileReading) {
    constexpr int kPoints = 200000;
    std::string file = pcdHeader(kFloatXyz, kPoints, 1, "binary");
    for (int i = 0; i < kPoints; ++i) {
        appendBytes(file, static_cast<float>(i));
        appendBytes(file, 0.0f);
        appendBytes(file, 0.0f);
    }
    std::vector<double> fractions;
    ReadContext context;
    context.progress = [&](double fraction) { fractions.push_back(fraction); };
    const PointCloud cloud = readPcd(test::asBytes(file), context);
    EXPECT_EQ(cloud.size(), static_cast<std::size_t>(kPoints));
    // Every 65536 points, then once at the end.
    ASSERT_EQ(fractions.size(), 4u);
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_EQ(fractions.back(), 1.0);
}

std::string truncatedBinary() {
    std::string file = pcdHeader(kFloatXyz, 3, 1, "binary");
    for (int i = 0; i < 7; ++i) {  // 2 points and a third of one
        appendBytes(file, 1.0f);
    }
    return file;
}

std::string compressedFile(const std::string& block) {
    return pcdHeader(kFloatXyz, 2, 1, "binary_compressed") + block;
}

std::string twoFloatPoints() {
    std::string columns;
    for (int i = 0; i < 6; ++i) {
        appendBytes(columns, static_cast<float>(i));
    }
    return columns;
}

/// LZF back reference to before the start of the output: lzf_decompress rejects it.
std::string corruptLzfFile() {
    const std::string stream = std::string("\x00\x41", 2) + "\xe0\xff\x10";
    return compressedFile(sizeHeader(static_cast<std::uint32_t>(stream.size()), 24) + stream);
}

std::string nonNumericAscii() {
    return pcdHeader(kFloatXyz, 2, 1, "ascii") + "1 2 3\n4 five 6\n";
}

TEST(PcdReaderTest, BadInputsGiveOneClearSentence) {
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    const std::string literals24 = lzfLiterals(twoFloatPoints());
    const std::string literals12 = lzfLiterals(twoFloatPoints().substr(0, 12));
    const Case cases[] = {
        {"SIZE length", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "lists 3 FIELDS but 2 SIZE values (line 2)"},
        {"TYPE length", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F F\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "lists 3 FIELDS but 4 TYPE values"},
        {"COUNT length",
         "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "lists 3 FIELDS but 2 COUNT values"},
        {"WIDTH x HEIGHT != POINTS",
         "FIELDS x y z\nWIDTH 640\nHEIGHT 480\nPOINTS 1000\nDATA ascii\n1 2 3\n",
         "WIDTH x HEIGHT (640 x 480 = 307200) does not equal its POINTS (1000)"},
        {"WIDTH x HEIGHT overflows",
         "FIELDS x y z\nWIDTH 4294967296\nHEIGHT 4294967296\nDATA ascii\n1 2 3\n", "is too large"},
        {"unknown TYPE", "FIELDS x y z\nSIZE 4 4 4\nTYPE F Q F\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "field 'y' has the unknown TYPE 'Q'"},
        {"float of 2 bytes", "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "field 'z' has TYPE F with SIZE 2"},
        {"SIZE 3", "FIELDS x y z\nSIZE 4 3 4\nTYPE F U F\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "field 'y' has SIZE '3'"},
        {"negative COUNT",
         "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 -1\nPOINTS 1\nDATA ascii\n1 2 3\n",
         "COUNT '-1', which is not a non-negative integer"},
        {"huge COUNT",
         "FIELDS x y z d\nSIZE 4 4 4 8\nTYPE F F F F\nCOUNT 1 1 1 18446744073709551615\n"
         "POINTS 1\nDATA binary\n",
         "more than 1073741824 bytes per point"},
        {"missing z", "FIELDS x y\nPOINTS 1\nDATA ascii\n1 2\n", "no 'z' field"},
        {"x with COUNT 2",
         "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 2 1 1\nPOINTS 1\nDATA ascii\n1 1 2 3\n",
         "field 'x' has COUNT 2, but a coordinate must be one value per point"},
        {"no FIELDS", "VERSION 0.7\nPOINTS 1\nDATA ascii\n1 2 3\n", "no FIELDS line"},
        {"empty FIELDS", "FIELDS\nPOINTS 1\nDATA ascii\n", "names no fields"},
        {"missing DATA", "VERSION 0.7\nFIELDS x y z\nPOINTS 1\n", "no DATA line"},
        {"unknown DATA", "FIELDS x y z\nPOINTS 1\nDATA binary_lz4\n", "unknown data kind"},
        {"DATA without kind", "FIELDS x y z\nPOINTS 1\nDATA\n", "should read 'DATA ascii'"},
        {"unknown keyword", "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nCOLOUR red\n",
         "PCD header line 4 'COLOUR red' is not a PCD header keyword"},
        {"header line of megabytes", "FIELDS" + std::string(2 << 20, ' ') + "x y z\n",
         "too long for a PCD header line"},
        {"repeated keyword", "FIELDS x y z\nFIELDS a b c\n",
         "repeats FIELDS, already given on line 1"},
        {"bad WIDTH", "FIELDS x y z\nWIDTH -3\nDATA ascii\n",
         "WIDTH -3' has a value that is not a non-negative"},
        {"HEIGHT without WIDTH", "FIELDS x y z\nHEIGHT 2\nDATA ascii\n", "HEIGHT but no WIDTH"},
        {"neither WIDTH nor POINTS", "FIELDS x y z\nDATA ascii\n", "neither WIDTH nor POINTS"},
        {"too many points", "FIELDS x y z\nPOINTS 4294967295\nDATA binary\n",
         "more than the 4294967294 points subscan can hold"},
        {"truncated binary", truncatedBinary(),
         "binary data holds 2 of the 3 points declared in the header"},
        {"compressed size header truncated", compressedFile("\x10\x00\x00"),
         "ends inside its 8-byte size header"},
        {"compressed data truncated", compressedFile(sizeHeader(100, 24) + literals24),
         "should have 100 compressed bytes, but only 25 follow"},
        {"corrupt LZF", corruptLzfFile(), "corrupt (LZF decompression failed)"},
        {"LZF too short",
         compressedFile(sizeHeader(static_cast<std::uint32_t>(literals12.size()), 24) + literals12),
         "unpacks to 12 bytes instead of 24"},
        {"LZF longer than announced",
         compressedFile(
             sizeHeader(static_cast<std::uint32_t>(literals24.size() + literals12.size()), 24) +
             literals24 + literals12),
         "corrupt (LZF decompression failed)"},
        {"uncompressed size != POINTS x stride",
         compressedFile(sizeHeader(static_cast<std::uint32_t>(literals24.size()), 20) + literals24),
         "unpacks to 20 bytes, but 2 points of 12 bytes need 24"},
        {"absurd uncompressed size",
         pcdHeader(kFloatXyz, 357913940, 1, "binary_compressed") +
             sizeHeader(static_cast<std::uint32_t>(literals24.size()), 4294967280u) + literals24,
         "claims to unpack 25 compressed bytes to 4294967280, more than LZF can"},
        {"non-numeric ascii", nonNumericAscii(), "PCD line 13 has the non-numeric value 'five'"},
        {"non-numeric rgb",
         pcdHeader("FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n", 1, 1, "ascii") +
             "1 2 3 red\n",
         "PCD line 12 has the non-numeric value 'red'"},
        {"number glued to text", pcdHeader(kFloatXyz, 1, 1, "ascii") + "1 2 3abc\n",
         "non-numeric value '3abc'"},
        {"too few values", pcdHeader(kFloatXyz, 2, 1, "ascii") + "1 2 3\n4 5\n",
         "PCD line 13 has 2 values, but the header's fields need 3"},
        {"ascii POINTS larger than the data",
         pcdHeader(kFloatXyz, 3, 1, "ascii") + "1 2 3\n\n4 5 6\n",
         "ascii data ends after 2 of the 3 points declared in the header"},
        {"zero points ascii", pcdHeader(kFloatXyz, 0, 1, "ascii"), "contains no points"},
        {"zero points binary", pcdHeader(kFloatXyz, 0, 1, "binary"), "contains no points"},
        {"zero points compressed", pcdHeader(kFloatXyz, 0, 1, "binary_compressed"),
         "contains no points"},
        {"all NaN", pcdHeader(kFloatXyz, 2, 1, "ascii") + "nan 0 0\n0 nan 0\n",
         "all 2 points have NaN"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_THAT(decodeError(c.file, "x.pcd"), HasSubstr(c.expected));
    }
}

TEST(PcdReaderTest, LyingSizesDoNotAllocateOrHang) {
    // Each would need gigabytes if the reader trusted the header before checking the data.
    const auto start = std::chrono::steady_clock::now();
    std::string binary = pcdHeader(kFloatXyz, 4000000000, 1, "binary");
    appendBytes(binary, 1.0f);
    EXPECT_THAT(decodeError(binary, "huge.pcd"), HasSubstr("holds 0 of the 4000000000 points"));
    const std::string ascii = pcdHeader(kFloatXyz, 4000000000, 1, "ascii") + "1 2 3\n";
    EXPECT_THAT(decodeError(ascii, "huge.pcd"), HasSubstr("ends after 1 of the 4000000000"));
    const std::string compressed =
        pcdHeader(kFloatXyz, 357913940, 1, "binary_compressed") + sizeHeader(0, 4294967280u);
    EXPECT_THAT(decodeError(compressed, "huge.pcd"), HasSubstr("more than LZF can"));
    // Generous: each case reads a few dozen bytes; only allocating or looping takes long.
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST(PcdReaderTest, CliReportsBadFilesInOneLine) {
    const test::TempDir directory;
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    const Case cases[] = {
        {"truncated.pcd", truncatedBinary(), "holds 2 of the 3 points"},
        {"corrupt.pcd", corruptLzfFile(), "LZF decompression failed"},
        {"text.pcd", nonNumericAscii(), "non-numeric value 'five'"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::string path = directory.write(c.name, c.file).string();
        const test::CommandResult result = test::runSubscan({"info", path});
        EXPECT_EQ(result.exitCode, 1);
        EXPECT_EQ(result.out, "");
        ASSERT_FALSE(result.err.empty());
        EXPECT_EQ(result.err.find('\n'), result.err.size() - 1) << result.err;
        EXPECT_THAT(result.err, HasSubstr(path + ": "));
        EXPECT_THAT(result.err, HasSubstr(c.expected));
    }
}

TEST(PcdReaderTest, RealScans) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    auto load = [&](const char* name) { return loadScan((data / name).string()); };

    const LoadedScan mug = load("table_scene_mug_stereo_textured.pcd");
    EXPECT_EQ(mug.formatDetail, "PCD 0.7 binary_compressed, organised 640x480");
    EXPECT_EQ(mug.cloud.size(), 209280u);
    EXPECT_THAT(mug.warnings, Contains(HasSubstr("dropped 97920 of 307200 points")));
    ASSERT_TRUE(mug.cloud.hasColors());
    // The first finite point is grid cell 6538, rgba 0xff43433e.
    EXPECT_EQ(mug.cloud.colors[0], (Rgba8{0x43, 0x43, 0x3e, 0xff}));
    // Stored as float32; positions relative to the centre of a 2 m cloud keep 1e-7 m steps.
    EXPECT_NEAR(mug.cloud.fileCoordinates(0).z, 2.0257999897003174, 1e-6);

    const LoadedScan isprs = load("isprs_CSite2_orig-utm.pcd");
    EXPECT_EQ(isprs.cloud.size(), 486800u);
    // UTM zone 32U northing: the bounds stay in file coordinates, not re-centred ones.
    EXPECT_GT(isprs.cloud.bounds.min.y, 5.40e6);
    EXPECT_LT(isprs.cloud.bounds.max.y, 5.41e6);
    EXPECT_GT(isprs.cloud.bounds.min.x, 5.1e5);
    // float32 near 5.4e6 has 0.5 m steps, so every y in the file is a multiple of 0.5.
    EXPECT_EQ(std::fmod(isprs.cloud.bounds.min.y, 0.5), 0.0);

    const LoadedScan autzen = load("autzen_utm_binary.pcd");
    EXPECT_EQ(autzen.formatDetail, "PCD 0.7 binary, unorganised");
    EXPECT_EQ(autzen.cloud.size(), 1065u);
    // Doubles in the file: exact bounds.
    EXPECT_EQ(autzen.cloud.bounds.min, glm::dvec3(493994.87, 4877429.62, 123.93));
    EXPECT_EQ(autzen.cloud.bounds.max, glm::dvec3(494993.68, 4878817.0200000005, 178.73));
    ASSERT_TRUE(autzen.cloud.hasColors());
    // Red Green Blue are uint16 holding 0..255: kept as they are.
    EXPECT_EQ(autzen.cloud.colors[0], (Rgba8{68, 77, 88, 255}));
    ASSERT_TRUE(autzen.cloud.hasIntensities());
    EXPECT_EQ(autzen.cloud.intensities[0], 143.0f);

    EXPECT_EQ(load("room_scan1.pcd").cloud.size(), 112586u);

    const LoadedScan bunny = load("pcl_bunny_ascii.pcd");
    EXPECT_EQ(bunny.formatDetail, "PCD 0.5 ascii, unorganised");
    EXPECT_EQ(bunny.cloud.size(), 397u);
    // Parsed from text straight into double: exact.
    EXPECT_EQ(bunny.cloud.bounds.min, glm::dvec3(-0.093938, 0.03742, -0.055026));
    EXPECT_EQ(bunny.cloud.bounds.max, glm::dvec3(0.059562, 0.1845, 0.057803));
}

}  // namespace
}  // namespace subscan
