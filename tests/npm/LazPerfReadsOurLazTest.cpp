// laz-perf (npm; LASzip's decoder compiled to WebAssembly, an implementation independent of ours)
// reads the LAZ files our writer writes to exactly the records we encoded: point formats 6, 7
// and 8 with extra bytes, every field varying, all four scanner channels, variable chunks of one
// to thousands of points. The package comes from tests/npm's lock file, installed into the build
// folder by the npm_packages test (install-packages.sh); without node, npm or the registry these
// tests are skipped and say why.
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/LazWriter.h"
#include "npm/NpmPackages.h"
#include "support/Las14Records.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

class LazPerfReadsOurLazTest : public ::testing::TestWithParam<test::Las14Format> {};

TEST_P(LazPerfReadsOurLazTest, ToTheRecordsWeEncoded) {
    const test::NpmPackages packages = test::npmPackages();
    if (!packages.unavailable.empty()) {
        GTEST_SKIP() << "laz-perf is not available: " << packages.unavailable;
    }
    const auto [format, extra] = GetParam();
    constexpr std::size_t kPoints = 20000;
    const std::vector<std::byte> records = test::randomLas14Records(
        {format, extra, true, static_cast<std::uint32_t>(1000 + 10 * format + extra)}, kPoints);
    LazFileContents contents;
    contents.header = test::las14Header(format, test::las14RecordLength(format, extra), kPoints);
    contents.vlrs.push_back({"subscan", 1, "a VLR before laszip's", {std::byte{42}}});
    contents.records = records;
    contents.chunkPointCounts = {1, 4999, 2, 10000, 1, 4997};
    contents.extendedVlrs.push_back({"subscan", 2, "an EVLR after the table", {std::byte{7}}});

    const test::TempDir dir;
    writeLaz(dir / "ours.laz", contents);
    const test::CommandResult result = test::runProgram(
        packages.node, {(packages.directory / "read-laz.js").string(), (dir / "ours.laz").string(),
                        (dir / "theirs.records").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out,
                HasSubstr(fmt::format("\"pointFormat\":{},\"pointLength\":{},"
                                      "\"pointCount\":{}",
                                      format, test::las14RecordLength(format, extra), kPoints)));
    const std::string theirs = test::fileBytes(dir / "theirs.records");
    ASSERT_EQ(theirs.size(), records.size());
    const std::size_t length = test::las14RecordLength(format, extra);
    std::size_t different = 0;
    for (std::size_t i = 0; i < kPoints; ++i) {
        if (std::memcmp(theirs.data() + i * length, records.data() + i * length, length) != 0 &&
            different++ < 3) {
            ADD_FAILURE() << "laz-perf reads point " << i << " otherwise";
        }
    }
    EXPECT_EQ(different, 0u);
}

INSTANTIATE_TEST_SUITE_P(Formats, LazPerfReadsOurLazTest,
                         ::testing::Values(test::Las14Format{6, 0}, test::Las14Format{6, 4},
                                           test::Las14Format{7, 0}, test::Las14Format{7, 2},
                                           test::Las14Format{8, 0}, test::Las14Format{8, 3}),
                         [](const ::testing::TestParamInfo<test::Las14Format>& format) {
                             return test::las14FormatName(format.param);
                         });

}  // namespace
}  // namespace subscan
