// subscan index on the real scans of the shared folder: LAS, LAZ, COPC, PLY, E57 and XYZ text
// each become a COPC file that gives back every input point exactly once with every attribute,
// as the record sources read them (PointRecordSourceDataTest ties those to the files' own
// fields); LAS-family inputs keep their scale and offset, so positions stay on the input's
// integer grid bit for bit.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "io/PointRecordSource.h"
#include "support/PointRecordTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::sortedRecords;

using ::testing::HasSubstr;

/// Indexes `input` and checks the COPC file against the input's records.
void expectIndexGivesBackEveryRecord(const std::filesystem::path& input) {
    const test::TempDir folder;
    const std::filesystem::path output = folder / "out.copc.laz";
    const test::CommandResult result =
        test::runSubscan({"index", input.string(), "-o", output.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;

    const std::unique_ptr<PointRecordSource> source = openPointRecordSource(input);
    const std::vector<std::byte> expected = test::readAllRecords(*source, 1 << 16);
    const MappedFile file(output);
    ReadContext context;
    const LasRecords written = readLasRecords(file.bytes(), context);
    EXPECT_THAT(context.formatDetail, HasSubstr("COPC 1.0"));
    EXPECT_EQ(written.pointFormat, source->info().format.pointFormat);
    ASSERT_EQ(written.recordLength, source->info().format.recordLength());
    EXPECT_EQ(written.size(), source->info().pointCount);
    EXPECT_TRUE(sortedRecords(written.bytes, written.recordLength) ==
                sortedRecords(expected, written.recordLength))
        << input << ": the COPC file's records are not the input's";
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(
            loadLittleEndian<double>(file.bytes().data() + las::header_field::kScale + 8 * axis),
            source->info().quantization.scale[axis]);
        EXPECT_EQ(
            loadLittleEndian<double>(file.bytes().data() + las::header_field::kOffset + 8 * axis),
            source->info().quantization.offset[axis]);
    }
}

class IndexDataTest : public testing::TestWithParam<std::string> {};

TEST_P(IndexDataTest, EveryPointOnceWithEveryAttribute) {
    const std::optional<std::filesystem::path> data = test::testDataDirectory();
    if (!data) {
        GTEST_SKIP() << "../shared/data (or $SUBSCAN_TEST_DATA) is absent on this machine";
    }
    expectIndexGivesBackEveryRecord(*data / GetParam());
}

/// A test's name from its file's: letters and digits, '_' for the rest.
std::string fileTestName(const testing::TestParamInfo<std::string>& param) {
    std::string name = param.param;
    std::replace_if(
        name.begin(), name.end(), [](char c) { return !std::isalnum(c); }, '_');
    return name;
}

INSTANTIATE_TEST_SUITE_P(SharedScans, IndexDataTest,
                         testing::Values("autzen_trim.las", "autzen_trim.laz", "lone_star.laz",
                                         "lone_star.copc.laz", "autzen_trim_las14_pf7.las",
                                         "bun_zipper.ply", "bunnyDouble.e57"),
                         fileTestName);

/// The records of any scan as the sources read them, with the quantization they are on.
struct ReadBack {
    std::vector<std::string> records;  // sorted
    Quantization quantization;
};

ReadBack readBack(const std::filesystem::path& path) {
    const std::unique_ptr<PointRecordSource> source = openPointRecordSource(path);
    const std::vector<std::byte> bytes = test::readAllRecords(*source, 1 << 16);
    return {sortedRecords(bytes, source->info().format.recordLength()),
            source->info().quantization};
}

class LasFamilyConvertDataTest : public testing::TestWithParam<std::string> {};

// Between LAS, LAZ and COPC, convert keeps the integer coordinates on the input's grid and every
// attribute, both ways: the input to each, and each of those back to LAS.
TEST_P(LasFamilyConvertDataTest, EveryRecordUnchangedBothWays) {
    const std::optional<std::filesystem::path> data = test::testDataDirectory();
    if (!data) {
        GTEST_SKIP() << "../shared/data (or $SUBSCAN_TEST_DATA) is absent on this machine";
    }
    const std::filesystem::path input = *data / GetParam();
    const ReadBack original = readBack(input);
    const test::TempDir folder;
    for (const std::string name : {"out.las", "out.laz", "out.copc.laz"}) {
        const std::filesystem::path output = folder / name;
        const test::CommandResult there =
            test::runSubscan({"convert", input.string(), "-o", output.string()});
        ASSERT_EQ(there.exitCode, 0) << there.err;
        const ReadBack converted = readBack(output);
        EXPECT_EQ(converted.quantization, original.quantization) << name;
        EXPECT_TRUE(converted.records == original.records) << input << " -> " << name;

        const std::filesystem::path back = folder / ("back-" + std::string(name) + ".las");
        const test::CommandResult again =
            test::runSubscan({"convert", output.string(), "-o", back.string()});
        ASSERT_EQ(again.exitCode, 0) << again.err;
        EXPECT_TRUE(readBack(back).records == original.records) << name << " -> LAS";
    }
}

INSTANTIATE_TEST_SUITE_P(SharedScans, LasFamilyConvertDataTest,
                         testing::Values("autzen_trim.las", "autzen_trim.laz", "simple.las",
                                         "autzen_trim_las14_pf7.las", "lone_star.laz",
                                         "lone_star.copc.laz"),
                         fileTestName);

TEST(IndexDataTest, TheSourcesWarningsReachTheUser) {
    const std::optional<std::filesystem::path> data = test::testDataDirectory();
    if (!data) {
        GTEST_SKIP() << "../shared/data (or $SUBSCAN_TEST_DATA) is absent on this machine";
    }
    // lone_star.laz gives its coordinate system as GeoTIFF keys only: the output has no WKT,
    // and index says so.
    const test::TempDir folder;
    const std::filesystem::path input = *data / "lone_star.laz";
    const test::CommandResult result =
        test::runSubscan({"index", input.string(), "-o", (folder / "out.copc.laz").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, HasSubstr("subscan: warning: " + input.string() +
                                      ": its coordinate system is given only as GeoTIFF keys"));
}

TEST(IndexDataTest, XyzTextEveryPointOnce) {
    const std::optional<std::filesystem::path> data = test::testDataDirectory();
    if (!data) {
        GTEST_SKIP() << "../shared/data (or $SUBSCAN_TEST_DATA) is absent on this machine";
    }
    // The shared folder has no XYZ file: the bunny written as one by convert.
    const test::TempDir folder;
    const std::filesystem::path xyz = folder / "bunny.xyz";
    const test::CommandResult converted =
        test::runSubscan({"convert", (*data / "bun_zipper.ply").string(), "-o", xyz.string()});
    ASSERT_EQ(converted.exitCode, 0) << converted.err;
    expectIndexGivesBackEveryRecord(xyz);
}

}  // namespace
}  // namespace subscan
