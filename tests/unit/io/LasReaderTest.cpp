#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::appendBytes;
using test::decode;
using test::decodeError;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

/// Record sizes and RGB positions of point formats 0-10, restated from LAS 1.4 R15 section 2.6
/// independently of the reader's own table.
constexpr std::array<std::size_t, 11> kRecordSizes{20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr std::array<int, 11> kColorOffsets{-1, -1, 20, 28, -1, 28, -1, 30, 30, -1, 30};

/// The LAS version that introduced each point format.
int firstMinorVersion(int pointFormat) {
    if (pointFormat <= 1) {
        return 0;
    }
    if (pointFormat <= 3) {
        return 2;
    }
    return pointFormat <= 5 ? 3 : 4;
}

struct LasPoint {
    std::array<std::int32_t, 3> stored{};  // the raw X, Y, Z integers
    std::uint16_t intensity = 0;
    std::array<std::uint16_t, 3> rgb{};
    std::optional<std::uint8_t> classificationByte;  // the whole byte, flags included
};

/// What the test writer puts in the header; the defaults make a valid LAS 1.2 format 3 file.
struct LasLayout {
    int versionMajor = 1;
    int versionMinor = 2;
    int pointFormat = 3;
    std::optional<std::size_t> recordLength;       // default: the format's size
    std::optional<std::size_t> headerSize;         // default: what the version needs
    std::optional<std::uint32_t> pointDataOffset;  // default: right after header and VLRs
    std::optional<std::uint32_t> legacyCount;      // default: the number of points
    std::optional<std::uint64_t> count64;          // 1.4 only; default: the number of points
    std::optional<std::uint8_t> formatByte;        // default: pointFormat (which stays 0-10)
    std::array<double, 3> scale{0.01, 0.01, 0.01};
    std::array<double, 3> offset{0.0, 0.0, 0.0};
    std::optional<std::array<double, 6>> bounds;  // max x, min x, max y, ...; default: exact
    bool laszipVlr = false;
};

std::size_t headerSizeFor(int versionMinor) {
    return versionMinor <= 2 ? 227 : versionMinor == 3 ? 235 : 375;
}

double fileCoordinate(const LasLayout& layout, const LasPoint& point, int axis) {
    return point.stored[axis] * layout.scale[axis] + layout.offset[axis];
}

template <class T>
void putAt(std::string& bytes, std::size_t offset, T value) {
    std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

/// A minimal LAS writer: header, optional laszip VLR, then the records. Fields the reader must
/// ignore (GPS time, classification, extra bytes...) are filled with 0xEE so a wrong offset shows.
std::string writeLas(const LasLayout& layout, const std::vector<LasPoint>& points) {
    const std::size_t headerSize = layout.headerSize.value_or(headerSizeFor(layout.versionMinor));
    // A header declared smaller than the 1.0 fields still gets room for them, so bad-size cases
    // differ from a valid file only in the size field.
    std::string file(std::max<std::size_t>(headerSize, 227), '\0');
    std::memcpy(file.data(), "LASF", 4);
    putAt<std::uint8_t>(file, 24, static_cast<std::uint8_t>(layout.versionMajor));
    putAt<std::uint8_t>(file, 25, static_cast<std::uint8_t>(layout.versionMinor));
    putAt<std::uint16_t>(file, 94, static_cast<std::uint16_t>(headerSize));
    putAt<std::uint32_t>(file, 100, layout.laszipVlr ? 1 : 0);
    putAt<std::uint8_t>(file, 104,
                        layout.formatByte.value_or(static_cast<std::uint8_t>(layout.pointFormat)));
    const std::size_t formatSize = kRecordSizes[layout.pointFormat];
    const std::size_t recordLength = layout.recordLength.value_or(formatSize);
    putAt<std::uint16_t>(file, 105, static_cast<std::uint16_t>(recordLength));
    putAt<std::uint32_t>(file, 107,
                         layout.legacyCount.value_or(static_cast<std::uint32_t>(points.size())));
    for (int axis = 0; axis < 3; ++axis) {
        putAt<double>(file, 131 + 8 * axis, layout.scale[axis]);
        putAt<double>(file, 155 + 8 * axis, layout.offset[axis]);
    }
    std::array<double, 6> bounds{};
    if (layout.bounds) {
        bounds = *layout.bounds;
    } else if (!points.empty()) {
        for (int axis = 0; axis < 3; ++axis) {
            double lo = fileCoordinate(layout, points[0], axis), hi = lo;
            for (const LasPoint& point : points) {
                lo = std::min(lo, fileCoordinate(layout, point, axis));
                hi = std::max(hi, fileCoordinate(layout, point, axis));
            }
            bounds[2 * axis] = hi;
            bounds[2 * axis + 1] = lo;
        }
    }
    for (int i = 0; i < 6; ++i) {
        putAt<double>(file, 179 + 8 * i, bounds[i]);
    }
    if (headerSize >= 255 && layout.versionMinor >= 4) {
        putAt<std::uint64_t>(file, 247, layout.count64.value_or(points.size()));
    }
    if (layout.laszipVlr) {
        std::string vlr(54, '\0');
        std::memcpy(vlr.data() + 2, "laszip encoded", 14);
        putAt<std::uint16_t>(vlr, 18, 22204);
        putAt<std::uint16_t>(vlr, 20, 4);
        file += vlr + std::string(4, '\x01');
    }
    const std::size_t naturalOffset = file.size();
    putAt<std::uint32_t>(
        file, 96, layout.pointDataOffset.value_or(static_cast<std::uint32_t>(naturalOffset)));

    const int colorOffset = kColorOffsets[layout.pointFormat];
    for (const LasPoint& point : points) {
        // Room for every field even when the declared length is too short; cut to it below.
        std::string record(std::max(recordLength, formatSize), '\xEE');
        for (int axis = 0; axis < 3; ++axis) {
            putAt<std::int32_t>(record, 4 * axis, point.stored[axis]);
        }
        putAt<std::uint16_t>(record, 12, point.intensity);
        if (point.classificationByte) {
            // LAS 1.4 R15 tables 7 and 13: byte 15 in formats 0-5, byte 16 in formats 6-10.
            putAt<std::uint8_t>(record, layout.pointFormat < 6 ? 15 : 16,
                                *point.classificationByte);
        }
        if (colorOffset >= 0) {
            for (int channel = 0; channel < 3; ++channel) {
                putAt<std::uint16_t>(record, colorOffset + 2 * channel, point.rgb[channel]);
            }
        }
        record.resize(recordLength);
        file += record;
    }
    return file;
}

std::vector<LasPoint> threePoints() {
    return {
        {{100, -200, 300}, 7, {0, 32768, 65535}},
        {{-5, 0, 2147483647}, 65535, {257, 514, 65280}},
        {{0, 1, -2147483647 - 1}, 0, {128, 129, 65407}},
    };
}

TEST(LasReaderTest, CoordinatesIntensityAndFormatDetailRoundTrip) {
    LasLayout layout;
    layout.scale = {0.5, 0.25, 1.0};
    layout.offset = {10.0, -20.0, 0.0};
    const std::vector<LasPoint> points = {
        {{2, 4, 6}, 1, {}}, {{-2, 0, 1}, 65535, {}}, {{0, -4, 3}, 300, {}}};
    const LoadedScan scan = decode(writeLas(layout, points), "round.las");
    EXPECT_EQ(scan.format, "las");
    EXPECT_EQ(scan.formatDetail, "LAS 1.2, point format 3");
    EXPECT_THAT(scan.warnings, IsEmpty());
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), 3u);
    // Every value here is a small binary fraction: float positions and doubles hold it exactly.
    EXPECT_EQ(cloud.fileCoordinates(0), glm::dvec3(11.0, -19.0, 6.0));
    EXPECT_EQ(cloud.fileCoordinates(1), glm::dvec3(9.0, -20.0, 1.0));
    EXPECT_EQ(cloud.fileCoordinates(2), glm::dvec3(10.0, -21.0, 3.0));
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(9.0, -21.0, 1.0));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(11.0, -19.0, 6.0));
    ASSERT_TRUE(cloud.hasIntensities());
    EXPECT_EQ(cloud.intensities, (std::vector<float>{1.0f, 65535.0f, 300.0f}));
    EXPECT_FALSE(cloud.hasNormals());
}

TEST(LasReaderTest, ClassificationIsTheClassCodeWithoutTheFlags) {
    // Formats 0-5: the upper 3 bits are the synthetic, key-point and withheld flags, set here
    // in every combination a code can hide behind; the code is the low 5 bits.
    LasLayout legacy;
    legacy.pointFormat = 1;
    std::vector<LasPoint> points(6);
    const std::uint8_t legacyBytes[] = {0, 2, 0x20 | 6, 0x40 | 9, 0xE0 | 2, 0x80 | 31};
    for (std::size_t i = 0; i < points.size(); ++i) {
        points[i].stored = {static_cast<std::int32_t>(i), 0, 0};
        points[i].classificationByte = legacyBytes[i];
    }
    const PointCloud fromLegacy = decode(writeLas(legacy, points), "legacy.las").cloud;
    ASSERT_TRUE(fromLegacy.hasClassifications());
    EXPECT_EQ(fromLegacy.classifications, (std::vector<std::uint8_t>{0, 2, 6, 9, 2, 31}));

    // Formats 6-10: the code has a byte of its own (the flags moved to byte 15, which the
    // writer leaves 0xEE), so codes above 31 exist.
    LasLayout extended;
    extended.versionMinor = 4;
    extended.pointFormat = 6;
    const std::uint8_t extendedBytes[] = {0, 2, 6, 18, 64, 255};
    for (std::size_t i = 0; i < points.size(); ++i) {
        points[i].classificationByte = extendedBytes[i];
    }
    const PointCloud fromExtended = decode(writeLas(extended, points), "extended.las").cloud;
    EXPECT_EQ(fromExtended.classifications, (std::vector<std::uint8_t>{0, 2, 6, 18, 64, 255}));
}

TEST(LasReaderTest, LargeUtmOffsetsKeepBoundsExactToTheScale) {
    LasLayout layout;
    layout.scale = {0.001, 0.001, 0.001};
    layout.offset = {500000.0, 5000000.0, 0.0};
    // Millimetre steps around UTM easting 500 km and northing 5000 km.
    const std::vector<LasPoint> points = {
        {{123, 456, 789}, 0, {}}, {{1234567, -987654, 1}, 0, {}}, {{-1, 1000000, 250000}, 0, {}}};
    const PointCloud cloud = decode(writeLas(layout, points), "utm.las").cloud;
    ASSERT_EQ(cloud.size(), 3u);
    // The reader must compute X * scale + offset in double: the bounds are then bit-identical.
    EXPECT_EQ(cloud.bounds.min.x, -1 * 0.001 + 500000.0);
    EXPECT_EQ(cloud.bounds.max.x, 1234567 * 0.001 + 500000.0);
    EXPECT_EQ(cloud.bounds.min.y, -987654 * 0.001 + 5000000.0);
    EXPECT_EQ(cloud.bounds.max.y, 1000000 * 0.001 + 5000000.0);
    // And they are the decimal millimetre values: doubles near 5e6 have steps of 1e-9, far
    // below half a millimetre step.
    EXPECT_NEAR(cloud.bounds.min.x, 499999.999, 1e-8);
    EXPECT_NEAR(cloud.bounds.max.x, 501234.567, 1e-8);
    EXPECT_NEAR(cloud.bounds.min.y, 4999012.346, 1e-8);
    EXPECT_NEAR(cloud.bounds.max.y, 5001000.0, 1e-8);
    EXPECT_NEAR(cloud.bounds.min.z, 0.001, 1e-12);
    EXPECT_NEAR(cloud.bounds.max.z, 250.0, 1e-12);
    // Positions are floats relative to the centre of a ~2 km box: float steps at 1 km are
    // 6e-5 m and a position is rounded twice (stored, then re-centred), so the error stays
    // below 1.2e-4 m, a quarter of a millimetre step with margin.
    EXPECT_NEAR(cloud.fileCoordinates(0).x, 500000.123, 2.5e-4);
    EXPECT_NEAR(cloud.fileCoordinates(0).y, 5000000.456, 2.5e-4);
    EXPECT_NEAR(cloud.fileCoordinates(0).z, 0.789, 2.5e-4);
}

TEST(LasReaderTest, SixteenBitColourIsReducedWithRounding) {
    const PointCloud cloud = decode(writeLas({}, threePoints()), "rgb16.las").cloud;
    ASSERT_TRUE(cloud.hasColors());
    // round(v / 257): 32768 -> 127.5 rounds up; 128 -> 0.498 down; 129 -> 0.502 up;
    // 65407 -> 254.5 up.
    EXPECT_EQ(cloud.colors[0], (Rgba8{0, 128, 255, 255}));
    EXPECT_EQ(cloud.colors[1], (Rgba8{1, 2, 254, 255}));
    EXPECT_EQ(cloud.colors[2], (Rgba8{0, 1, 255, 255}));
    EXPECT_TRUE(cloud.colorCutTo8Bits);  // convert says so of its 8-bit outputs
}

TEST(LasReaderTest, EightBitColourInSixteenBitFieldsIsTakenAsIs) {
    std::vector<LasPoint> points = threePoints();
    points[0].rgb = {0, 128, 255};
    points[1].rgb = {1, 2, 3};
    points[2].rgb = {200, 100, 50};
    const PointCloud cloud = decode(writeLas({}, points), "rgb8.las").cloud;
    ASSERT_TRUE(cloud.hasColors());
    EXPECT_EQ(cloud.colors[0], (Rgba8{0, 128, 255, 255}));
    EXPECT_EQ(cloud.colors[1], (Rgba8{1, 2, 3, 255}));
    EXPECT_EQ(cloud.colors[2], (Rgba8{200, 100, 50, 255}));
    EXPECT_FALSE(cloud.colorCutTo8Bits);

    // One value above 255 anywhere, even in the last point, makes the whole file 16-bit.
    points[2].rgb = {200, 100, 256};
    const PointCloud sixteen = decode(writeLas({}, points), "rgb16.las").cloud;
    EXPECT_EQ(sixteen.colors[0], (Rgba8{0, 0, 1, 255}));
    EXPECT_EQ(sixteen.colors[2], (Rgba8{1, 0, 1, 255}));
    EXPECT_TRUE(sixteen.colorCutTo8Bits);

    // 8-bit colour times 257, as writeLas stores it, is 16-bit colour that 8 bits give back.
    for (LasPoint& point : points) {
        for (auto& channel : point.rgb) {
            channel = static_cast<std::uint16_t>(channel % 256 * 257);
        }
    }
    EXPECT_FALSE(decode(writeLas({}, points), "rgb257.las").cloud.colorCutTo8Bits);
}

TEST(LasReaderTest, EveryPointFormatDecodesPositionsAndColour) {
    for (int format = 0; format <= 10; ++format) {
        for (int minor = firstMinorVersion(format); minor <= 4; ++minor) {
            SCOPED_TRACE(::testing::Message() << "LAS 1." << minor << " format " << format);
            LasLayout layout;
            layout.versionMinor = minor;
            layout.pointFormat = format;
            const LoadedScan scan = decode(writeLas(layout, threePoints()), "formats.las");
            EXPECT_EQ(scan.formatDetail, "LAS 1." + std::to_string(minor) + ", point format " +
                                             std::to_string(format));
            EXPECT_THAT(scan.warnings, IsEmpty());
            const PointCloud& cloud = scan.cloud;
            ASSERT_EQ(cloud.size(), 3u);
            // Same double expression as the reader (stored * scale + offset): bit-identical.
            EXPECT_EQ(cloud.bounds.min, glm::dvec3(-5 * 0.01, -200 * 0.01, -2147483648.0 * 0.01));
            EXPECT_EQ(cloud.bounds.max, glm::dvec3(100 * 0.01, 1 * 0.01, 2147483647 * 0.01));
            // x and y span about 1 around a centre near 0: float steps are below 1e-7 there.
            EXPECT_NEAR(cloud.fileCoordinates(0).x, 1.0, 1e-6);
            EXPECT_NEAR(cloud.fileCoordinates(0).y, -2.0, 1e-6);
            // z spans the whole int32 range (+-2.1e7 at scale 0.01) around a centre near 0: floats
            // there have steps of 2 and the builder rounds twice (relative to the first point,
            // then re-centred), so the position is within 2 of the exact value.
            EXPECT_NEAR(cloud.fileCoordinates(1).z, 2147483647 * 0.01, 2.0);
            EXPECT_EQ(cloud.intensities, (std::vector<float>{7.0f, 65535.0f, 0.0f}));
            EXPECT_EQ(cloud.hasColors(), kColorOffsets[format] >= 0);
            if (cloud.hasColors()) {
                EXPECT_EQ(cloud.colors[0], (Rgba8{0, 128, 255, 255}));
                EXPECT_EQ(cloud.colors[1], (Rgba8{1, 2, 254, 255}));
            }
        }
    }
}

TEST(LasReaderTest, PointFormatNewerThanTheVersionIsReadWithAWarning) {
    LasLayout layout;
    layout.versionMinor = 2;
    layout.pointFormat = 7;
    const LoadedScan scan = decode(writeLas(layout, threePoints()), "mixed.las");
    ASSERT_EQ(scan.cloud.size(), 3u);
    EXPECT_EQ(scan.cloud.colors[0], (Rgba8{0, 128, 255, 255}));
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("point format 7 is not defined before LAS 1.4")));
}

TEST(LasReaderTest, ExtraBytesAfterTheStandardFieldsAreSkipped) {
    for (const int format : {0, 3, 6, 10}) {
        SCOPED_TRACE(format);
        LasLayout layout;
        layout.versionMinor = 4;
        layout.pointFormat = format;
        layout.recordLength = kRecordSizes[format] + 13;  // odd, so records are unaligned
        const PointCloud cloud = decode(writeLas(layout, threePoints()), "extra.las").cloud;
        ASSERT_EQ(cloud.size(), 3u);
        EXPECT_EQ(cloud.bounds.min, glm::dvec3(-5 * 0.01, -200 * 0.01, -2147483648.0 * 0.01));
        EXPECT_EQ(cloud.intensities[1], 65535.0f);
        if (cloud.hasColors()) {
            EXPECT_EQ(cloud.colors[2], (Rgba8{0, 1, 255, 255}));
        }
    }
}

TEST(LasReaderTest, Las14UsesThe64BitPointCountWhereSet) {
    std::vector<LasPoint> points = threePoints();
    LasLayout layout;
    layout.versionMinor = 4;
    layout.pointFormat = 6;
    layout.legacyCount = 0;  // as 1.4 writers leave it for formats 6-10
    EXPECT_EQ(decode(writeLas(layout, points), "count64.las").cloud.size(), 3u);

    // The point data holds three records; counts that say two read only two.
    layout.legacyCount = 0;
    layout.count64 = 2;
    EXPECT_EQ(decode(writeLas(layout, points), "count64.las").cloud.size(), 2u);

    // A writer that ignores the 1.4 field leaves it 0: the legacy count applies.
    layout.legacyCount = 2;
    layout.count64 = 0;
    EXPECT_EQ(decode(writeLas(layout, points), "legacy.las").cloud.size(), 2u);

    // Both set and disagreeing: the 64-bit count wins, with a warning.
    layout.legacyCount = 2;
    layout.count64 = 3;
    const LoadedScan scan = decode(writeLas(layout, points), "both.las");
    EXPECT_EQ(scan.cloud.size(), 3u);
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("legacy point count 2 disagrees")));

    // Before 1.4 the bytes at offset 247 are not a count (here: inside a longer header).
    LasLayout old;
    old.versionMinor = 3;
    old.headerSize = 375;
    old.legacyCount = 2;
    std::string file = writeLas(old, points);
    putAt<std::uint64_t>(file, 247, 3);
    EXPECT_EQ(decode(file, "old.las").cloud.size(), 2u);
}

TEST(LasReaderTest, HeaderBoundsThatDisagreeGiveAWarning) {
    LasLayout layout;
    layout.scale = {0.01, 0.01, 0.01};
    const std::vector<LasPoint> points = {{{100, 200, 300}, 0, {}}, {{-100, 0, 0}, 0, {}}};
    // Within one scale step on every side: no warning.
    layout.bounds = {1.009, -1.009, 2.0, 0.0, 3.005, -0.005};
    EXPECT_THAT(decode(writeLas(layout, points), "close.las").warnings, IsEmpty());
    // Two scale steps off in max z: a warning, and the points' bounds are kept.
    layout.bounds = {1.0, -1.0, 2.0, 0.0, 3.02, 0.0};
    const LoadedScan scan = decode(writeLas(layout, points), "stale.las");
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("header bounds")));
    EXPECT_EQ(scan.cloud.bounds.max.z, 3.0);
}

TEST(LasReaderTest, ProgressIsReportedAndReachesOne) {
    std::vector<LasPoint> points(150000);
    for (std::size_t i = 0; i < points.size(); ++i) {
        points[i].stored = {static_cast<std::int32_t>(i), 0, 0};
    }
    LasLayout layout;
    layout.pointFormat = 0;
    const std::string file = writeLas(layout, points);
    std::vector<double> fractions;
    const LoadedScan scan =
        decodeScan(test::asBytes(file), ScanFormat::Las, [&](double f) { fractions.push_back(f); });
    EXPECT_EQ(scan.cloud.size(), points.size());
    ASSERT_GE(fractions.size(), 3u);  // 150,000 points: at 0, 65,536, 131,072 and the end
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_EQ(fractions.back(), 1.0);
}

TEST(LasReaderTest, BadInputsGiveOneClearSentence) {
    const std::vector<LasPoint> points = threePoints();
    const std::string valid = writeLas({}, points);
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    auto with = [&](auto change) {
        LasLayout layout;
        change(layout);
        return writeLas(layout, points);
    };
    std::string nanScale = valid;
    putAt<double>(nanScale, 139, std::nan(""));
    std::string infiniteOffset = valid;
    putAt<double>(infiniteOffset, 171, HUGE_VAL);
    const Case cases[] = {
        {"wrong signature", "LASX" + valid.substr(4), "does not start with the LAS signature"},
        {"signature cut short", "LAS", "does not start with the LAS signature"},
        {"shorter than any header", valid.substr(0, 100),
         "fewer than the 227 bytes of the smallest LAS header"},
        {"version 2.0", with([](LasLayout& layout) {
             layout.versionMajor = 2;
             layout.versionMinor = 0;
         }),
         "LAS version 2.0 is not supported"},
        {"version 1.5", with([](LasLayout& layout) { layout.versionMinor = 5; }),
         "LAS version 1.5 is not supported"},
        {"1.2 header too small", with([](LasLayout& layout) { layout.headerSize = 226; }),
         "declares a size of 226 bytes, less than the 227"},
        {"1.3 header too small", with([](LasLayout& layout) {
             layout.versionMinor = 3;
             layout.headerSize = 227;
         }),
         "less than the 235 bytes"},
        {"1.4 header too small", with([](LasLayout& layout) {
             layout.versionMinor = 4;
             layout.headerSize = 235;
         }),
         "less than the 375 bytes"},
        {"file shorter than its header",
         with([](LasLayout& layout) { layout.versionMinor = 4; }).substr(0, 300),
         "fewer than its 375-byte LAS header"},
        {"point data inside header", with([](LasLayout& layout) { layout.pointDataOffset = 100; }),
         "offset 100 lies inside the 227-byte header"},
        {"point data beyond file",
         with([](LasLayout& layout) { layout.pointDataOffset = 0xFFFFFFF0u; }),
         "offset 4294967280 lies beyond the end of the file"},
        {"record length too small", with([](LasLayout& layout) { layout.recordLength = 33; }),
         "record length 33 is shorter than the 34 bytes point format 3 needs"},
        {"record length zero", with([](LasLayout& layout) { layout.recordLength = 0; }),
         "record length 0 is shorter"},
        {"unknown point format", with([](LasLayout& layout) { layout.formatByte = 11; }),
         "point data format 11 is unknown"},
        {"count beyond the data", with([](LasLayout& layout) { layout.legacyCount = 4; }),
         "declares 4 points, but the point data holds only 3"},
        {"huge legacy count", with([](LasLayout& layout) { layout.legacyCount = 0xFFFFFFFFu; }),
         "declares 4294967295 points"},
        {"huge 64-bit count", with([](LasLayout& layout) {
             layout.versionMinor = 4;
             layout.count64 = 0xFFFFFFFFFFFFFFFFull;
         }),
         "declares 18446744073709551615 points"},
        {"truncated records", valid.substr(0, valid.size() - 1),
         "declares 3 points, but the point data holds only 2"},
        {"zero points", with([](LasLayout& layout) { layout.legacyCount = 0; }),
         "contains no points"},
        {"zero points 1.4", with([](LasLayout& layout) {
             layout.versionMinor = 4;
             layout.legacyCount = 0;
             layout.count64 = 0;
         }),
         "contains no points"},
        {"zero scale", with([](LasLayout& layout) { layout.scale[0] = 0.0; }),
         "x scale factor is 0; it must be a finite, non-zero number"},
        {"NaN scale", nanScale, "y scale factor is nan"},
        {"infinite offset", infiniteOffset, "z offset is inf"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_THAT(decodeError(c.file, "bad.las"), HasSubstr(c.expected));
    }
}

TEST(LasReaderTest, CompressionWithoutAUsableLaszipVlrIsRefused) {
    const std::vector<LasPoint> points = threePoints();
    auto with = [&](auto change) {
        LasLayout layout;
        change(layout);
        return writeLas(layout, points);
    };
    // The compression bits of the format byte without the laszip VLR that says how.
    const std::string laz = with([](LasLayout& layout) { layout.formatByte = 0x83; });
    const std::string layered = with([](LasLayout& layout) {
        layout.versionMinor = 4;
        layout.pointFormat = 7;
        layout.formatByte = 0xC7;
    });
    // A laszip VLR with the bits cleared still means the records are compressed; this one is too
    // short to describe anything.
    const std::string vlrOnly = with([](LasLayout& layout) { layout.laszipVlr = true; });
    for (const auto& [name, file, expected] :
         {std::tuple{"bit 7", laz,
                     "format byte 131 marks compressed (LAZ) points, but the file "
                     "has no laszip VLR"},
          std::tuple{"bits 6 and 7", layered, "format byte 199 marks compressed"},
          std::tuple{"laszip VLR", vlrOnly, "the laszip VLR has 4 bytes, fewer than the 34"}}) {
        SCOPED_TRACE(name);
        EXPECT_THAT(decodeError(file, "x.laz"), HasSubstr(expected));
    }
    // Other VLRs do not make a file compressed.
    std::string otherVlr = vlrOnly;
    std::memcpy(otherVlr.data() + 227 + 2, "LASF_Projection", 15);
    EXPECT_EQ(decode(otherVlr, "vlr.las").cloud.size(), 3u);
}

TEST(LasReaderTest, EveryTruncationAndCorruptionFailsCleanly) {
    // Every prefix, and random byte changes: each decodes or throws subscan::Error, nothing
    // else (the sanitizer build turns any out-of-bounds read into a failure). One file has a
    // VLR, so the VLR walk is corrupted too.
    std::mt19937 random(12345);
    for (const bool laszipVlr : {false, true}) {
        SCOPED_TRACE(laszipVlr ? "with VLR" : "no VLR");
        LasLayout layout;
        layout.versionMinor = 4;
        layout.pointFormat = 8;
        layout.laszipVlr = laszipVlr;
        const std::string file = writeLas(layout, threePoints());
        for (std::size_t size = 0; size <= file.size(); ++size) {
            try {
                decode(file.substr(0, size), "cut.las");
            } catch (const Error&) {
            }
        }
        for (int trial = 0; trial < 2000; ++trial) {
            std::string corrupted = file;
            for (int change = 0; change < 4; ++change) {
                corrupted[random() % corrupted.size()] = static_cast<char>(random());
            }
            try {
                decode(corrupted, "changed.las");
            } catch (const Error&) {
            }
        }
    }
}

TEST(LasReaderTest, CommandLineReportsBadFilesOnOneLine) {
    const test::TempDir directory;
    const std::vector<LasPoint> points = threePoints();
    LasLayout newVersion;
    newVersion.versionMinor = 7;
    LasLayout compressed;
    compressed.formatByte = 0x83;
    const std::string valid = writeLas({}, points);
    struct Case {
        const char* name;
        std::string bytes;
        const char* expected;
    };
    const Case cases[] = {
        {"version.las", writeLas(newVersion, points), "LAS version 1.7 is not supported"},
        {"truncated.las", valid.substr(0, valid.size() - 10), "file truncated"},
        {"packed.laz", writeLas(compressed, points), "has no laszip VLR"},
        {"notlas.las", "this is not a LAS file at all", "does not start with the LAS signature"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::filesystem::path path = directory.write(c.name, c.bytes);
        const test::CommandResult result = test::runSubscan({"info", path.string()});
        EXPECT_EQ(result.exitCode, 1);
        EXPECT_THAT(result.out, IsEmpty());
        ASSERT_FALSE(result.err.empty());
        EXPECT_EQ(result.err.find('\n'), result.err.size() - 1) << result.err;
        EXPECT_THAT(result.err, HasSubstr(path.string()));
        EXPECT_THAT(result.err, HasSubstr(c.expected));
    }
}

std::string readFile(const std::filesystem::path& path) {
    std::ifstream stream(path, std::ios::binary);
    std::ostringstream contents;
    contents << stream.rdbuf();
    return contents.str();
}

struct RealLasFile {
    const char* name;
    const char* formatDetail;
    std::size_t points;
    std::size_t groundPoints;  // class 2
};

TEST(LasReaderTest, RealFilesMatchTheirHeaders) {
    SUBSCAN_REQUIRE_TEST_DATA(directory);
    const RealLasFile files[] = {
        {"autzen_trim.las", "LAS 1.2, point format 3", 110000, 26107},
        {"autzen_trim_las14_pf7.las", "LAS 1.4, point format 7", 110000, 26107},
        {"simple.las", "LAS 1.2, point format 3", 1065, 276},
    };
    for (const RealLasFile& expected : files) {
        SCOPED_TRACE(expected.name);
        const std::filesystem::path path = directory / expected.name;
        const LoadedScan scan = loadScan(path.string());
        EXPECT_EQ(scan.formatDetail, expected.formatDetail);
        EXPECT_THAT(scan.warnings, IsEmpty());
        const PointCloud& cloud = scan.cloud;
        EXPECT_EQ(cloud.size(), expected.points);

        // The header's scale and min/max, read here straight from the bytes.
        const std::string bytes = readFile(path);
        ASSERT_GE(bytes.size(), 227u);
        auto headerDouble = [&](std::size_t offset) {
            double value = 0.0;
            std::memcpy(&value, bytes.data() + offset, sizeof value);
            return value;
        };
        for (int axis = 0; axis < 3; ++axis) {
            SCOPED_TRACE(axis);
            const double scale = headerDouble(131 + 8 * axis);
            // The header holds the extremes as the writer computed them, with its own rounding
            // (637179.2200000001 where we compute 637179.22); within half a scale step both
            // name the same point of the scale grid.
            EXPECT_NEAR(cloud.bounds.max[axis], headerDouble(179 + 16 * axis), 0.5 * scale);
            EXPECT_NEAR(cloud.bounds.min[axis], headerDouble(187 + 16 * axis), 0.5 * scale);
        }
        ASSERT_TRUE(cloud.hasColors());
        ASSERT_TRUE(cloud.hasIntensities());
        ASSERT_TRUE(cloud.hasClassifications());
        // Counted from the bytes by a separate script: every point is unclassified (1) or
        // ground (2), 83,893 and 26,107 of autzen's, 789 and 276 of simple.las'.
        const auto ground = static_cast<std::size_t>(
            std::count(cloud.classifications.begin(), cloud.classifications.end(), 2));
        const auto unclassified = static_cast<std::size_t>(
            std::count(cloud.classifications.begin(), cloud.classifications.end(), 1));
        EXPECT_EQ(ground, expected.groundPoints);
        EXPECT_EQ(ground + unclassified, expected.points);
        const bool anyColour =
            std::any_of(cloud.colors.begin(), cloud.colors.end(),
                        [](const Rgba8& c) { return c.r != 0 || c.g != 0 || c.b != 0; });
        EXPECT_TRUE(anyColour);
    }
}

}  // namespace
}  // namespace subscan
