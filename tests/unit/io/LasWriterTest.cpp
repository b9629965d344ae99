#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasWriter.h"
#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

template <class T>
T fieldAt(const std::string& bytes, std::size_t offset) {
    return loadLittleEndian<T>(bytes.data() + offset);
}

Bounds boundsOf(const glm::dvec3& min, const glm::dvec3& max) {
    Bounds bounds;
    bounds.add(min);
    bounds.add(max);
    return bounds;
}

TEST(LasWriterTest, ScalingIsTheFinestPowerOfTenThatFitsInt32) {
    // An airborne tile: offsets round down to whole hundreds or thousands (the largest power of
    // ten not above each extent). Then x reaches 1982.55 from its offset, 1.98e9 micrometres
    // (fits 2^31 - 1 = 2.147e9); y 4535.43 m needs 1e-5; z reaches 215.26 m, which at 1e-7 would
    // be 2.153e9 steps, just too many, so 1e-6.
    const LasScaling tile =
        chooseLasScaling(boundsOf({637012.24, 849028.31, 406.59}, {638982.55, 853535.43, 615.26}));
    EXPECT_EQ(tile.offset, glm::dvec3(637000.0, 849000.0, 400.0));
    EXPECT_EQ(tile.scale, glm::dvec3(1e-6, 1e-5, 1e-6));

    // One point: extent 0 counts as 1 m, so the offsets are whole numbers below it and the
    // finest scale, 1e-9, is taken.
    const LasScaling point =
        chooseLasScaling(boundsOf({5000000.123, -3.5, 0.0}, {5000000.123, -3.5, 0.0}));
    EXPECT_EQ(point.offset, glm::dvec3(5000000.0, -4.0, 0.0));
    EXPECT_EQ(point.scale, glm::dvec3(1e-9));

    // The widest cloud a reader keeps (kMaxCoordinate on both sides) still fits, at 1e6:
    // 2e15 / 1e6 = 2e9 steps.
    const LasScaling widest = chooseLasScaling(boundsOf(glm::dvec3(-1e15), glm::dvec3(1e15)));
    EXPECT_EQ(widest.scale, glm::dvec3(1e6));
    EXPECT_EQ(widest.offset, glm::dvec3(-1e15));

    try {
        chooseLasScaling(boundsOf(glm::dvec3(-1e17), glm::dvec3(1e17)));
        ADD_FAILURE() << "an extent of 2e17 cannot fit int32 at any scale up to 1e7";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("32-bit"));
    }
}

TEST(LasWriterTest, BytesHoldTheValuesComputedByHand) {
    const test::TempDir dir;
    const auto path = dir / "utm.las";
    writeLas(path, test::utmCloudWithEveryAttribute());
    const std::string bytes = test::fileBytes(path);
    constexpr std::size_t kHeader = 227;
    constexpr std::size_t kRecord = 26;  // point format 2: 20 bytes of format 0, then RGB
    ASSERT_EQ(bytes.size(), kHeader + 5 * kRecord);

    EXPECT_EQ(bytes.substr(0, 4), "LASF");
    EXPECT_EQ(fieldAt<std::uint8_t>(bytes, 24), 1);  // version 1.2
    EXPECT_EQ(fieldAt<std::uint8_t>(bytes, 25), 2);
    EXPECT_EQ(bytes.substr(26, 32), std::string("subscan") + std::string(25, '\0'));
    EXPECT_EQ(bytes.substr(58, 32), std::string("subscan") + std::string(25, '\0'));
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, 94), kHeader);
    EXPECT_EQ(fieldAt<std::uint32_t>(bytes, 96), kHeader);  // point data right after it
    EXPECT_EQ(fieldAt<std::uint32_t>(bytes, 100), 0u);      // no VLRs
    EXPECT_EQ(fieldAt<std::uint8_t>(bytes, 104), 2);
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, 105), kRecord);
    EXPECT_EQ(fieldAt<std::uint32_t>(bytes, 107), 5u);
    EXPECT_EQ(fieldAt<std::uint32_t>(bytes, 111), 5u);  // all first returns
    for (std::size_t r = 1; r < 5; ++r) {
        EXPECT_EQ(fieldAt<std::uint32_t>(bytes, 111 + 4 * r), 0u);
    }
    // The cloud spans 10 m from (512345.25, 5432109.5, 97): offsets round down to tens, and the
    // farthest coordinates lie 15.25, 19.5 and 17 m from them, which at 1e-9 would be ~1.9e10
    // steps (more than 2^31) and at 1e-8 ~1.9e9 (fits).
    const glm::dvec3 offset(512340.0, 5432100.0, 90.0);
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(fieldAt<double>(bytes, 131 + 8 * axis), 1e-8) << axis;
        EXPECT_EQ(fieldAt<double>(bytes, 155 + 8 * axis), offset[axis]) << axis;
    }
    // Max, min per axis: the corners, within a scale step's rounding of the double sum.
    const double bounds[] = {512355.25, 512345.25, 5432119.5, 5432109.5, 107.0, 97.0};
    for (int i = 0; i < 6; ++i) {
        EXPECT_NEAR(fieldAt<double>(bytes, 179 + 8 * i), bounds[i], 1e-8) << i;
    }

    // Point 1 is at (512355.25, 5432109.5, 97): 15.25, 9.5 and 7 m from the offset in 1e-8 steps.
    const std::size_t p = kHeader + kRecord;
    EXPECT_EQ(fieldAt<std::int32_t>(bytes, p), 1525000000);
    EXPECT_EQ(fieldAt<std::int32_t>(bytes, p + 4), 950000000);
    EXPECT_EQ(fieldAt<std::int32_t>(bytes, p + 8), 700000000);
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, p + 12), 1);    // intensity 1.25 rounded
    EXPECT_EQ(fieldAt<std::uint8_t>(bytes, p + 14), 0x09);  // return 1 of 1
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, p + 20), 60 * 257);
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, p + 22), 200 * 257);
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, p + 24), 254 * 257);
}

TEST(LasWriterTest, UtmCloudReadsBack) {
    const test::TempDir dir;
    const PointCloud cloud = test::utmCloudWithEveryAttribute();
    const auto path = dir / "utm.las";
    writeLas(path, cloud);
    const LoadedScan read = loadScan(path.string());
    EXPECT_EQ(read.formatDetail, "LAS 1.2, point format 2");
    EXPECT_TRUE(read.warnings.empty()) << read.warnings.front();  // header bounds agree too
    // Half the 1e-8 scale from rounding to it, and the last bits of the double sums around
    // 5e6 (a step there is 1e-9); the float positions in memory are exact (multiples of 0.25).
    test::expectPositionsNear(read.cloud, cloud, 0.5e-8 + 2e-9);
    // 8-bit colours survive the 16-bit detour exactly.
    EXPECT_EQ(read.cloud.colors, cloud.colors);
    // Rounded (half away from zero) and clamped to 0..65535.
    EXPECT_EQ(read.cloud.intensities, (std::vector<float>{0, 1, 3, 65535, 0}));
    EXPECT_FALSE(read.cloud.hasNormals());  // LAS 1.2 has no field for them
}

TEST(LasWriterTest, CloudWithoutColourIsPointFormat0) {
    const test::TempDir dir;
    PointCloudBuilder builder({}, 2);
    for (const double x : {-1.5, 2.25}) {
        PointRecord record;
        record.position = {x, 0.5, 0.0};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const auto path = dir / "plain.las";
    writeLas(path, cloud);
    const std::string bytes = test::fileBytes(path);
    EXPECT_EQ(fieldAt<std::uint8_t>(bytes, 104), 0);
    EXPECT_EQ(fieldAt<std::uint16_t>(bytes, 105), 20);
    EXPECT_EQ(bytes.size(), 227u + 2 * 20);
    const LoadedScan read = loadScan(path.string());
    EXPECT_FALSE(read.cloud.hasColors());
    EXPECT_EQ(read.cloud.intensities, (std::vector<float>{0, 0}));  // none to write: 0
    // x: offset -2, reaching 4.25 m, which takes a 1e-8 scale (4.25e9 steps of 1e-9 are more
    // than 2^31): half of it is the rounding; the float positions in memory are exact.
    test::expectPositionsNear(read.cloud, cloud, 0.5e-8);
}

TEST(LasWriterTest, ClassificationIsWrittenAndReadBack) {
    const test::TempDir dir;
    PointCloud cloud = test::utmCloudWithEveryAttribute();
    ASSERT_EQ(cloud.size(), 5u);
    // LAS 1.2 holds codes 0-31 (5 bits); 64 and 255 (from LAS 1.4 formats 6-10) become 1.
    cloud.classifications = {0, 2, 31, 64, 255};
    const auto path = dir / "classes.las";
    writeLas(path, cloud);
    const std::string bytes = test::fileBytes(path);
    constexpr std::size_t kHeader = 227;
    constexpr std::size_t kRecord = 26;  // point format 2
    const std::uint8_t expected[] = {0, 2, 31, 1, 1};
    for (std::size_t i = 0; i < 5; ++i) {
        // Byte 15: the code in the low 5 bits, the flags above it clear.
        EXPECT_EQ(fieldAt<std::uint8_t>(bytes, kHeader + i * kRecord + 15), expected[i]) << i;
    }
    EXPECT_EQ(loadScan(path.string()).cloud.classifications,
              (std::vector<std::uint8_t>{0, 2, 31, 1, 1}));
    // Without classification every point is 0, never classified.
    cloud.classifications.clear();
    writeLas(path, cloud);
    EXPECT_EQ(loadScan(path.string()).cloud.classifications, std::vector<std::uint8_t>(5, 0));
}

TEST(LasWriterTest, UnwritablePathIsAnErrorNamingIt) {
    test::expectUnwritablePathIsAnErrorNamingIt(
        [](const std::filesystem::path& path) {
            writeLas(path, test::utmCloudWithEveryAttribute());
        },
        "out.las");
}

}  // namespace
}  // namespace subscan
