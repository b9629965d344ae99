// subscan index as a user runs it: a scan in, a COPC file out that gives back every record;
// every way it can fail is one sentence, exit code 1, no output file and no temporary file.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/LasReader.h"
#include "io/LasWriter.h"
#include "io/MappedFile.h"
#include "io/PointRecordSource.h"
#include "support/PointRecordTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::sortedRecords;

using test::runSubscan;
using ::testing::HasSubstr;
using ::testing::StartsWith;

/// A LAS file of many points with every attribute (UTM coordinates), in `folder`.
std::filesystem::path lasInput(const test::TempDir& folder) {
    const std::filesystem::path input = folder / "input.las";
    writeLas(input, test::utmCloudWithEveryAttribute());
    return input;
}

TEST(IndexCommandTest, ALasFileBecomesACopcFileWithEveryRecord) {
    const test::TempDir folder;
    const std::filesystem::path input = lasInput(folder);
    const std::filesystem::path output = folder / "out.copc.laz";
    const test::CommandResult result =
        runSubscan({"index", input.string(), "-o", output.string(), "--threads", "2"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, StartsWith(output.string() + ": "));
    EXPECT_THAT(result.out, HasSubstr(" levels, "));
    EXPECT_EQ(test::folderEntries(folder.path()),
              (std::vector<std::string>{"input.las", "out.copc.laz"}));

    // The input's records as LAS 1.4 (what the source gives) against the COPC file's.
    const std::unique_ptr<PointRecordSource> source = openPointRecordSource(input);
    const std::vector<std::byte> expected = test::readAllRecords(*source, 1000);
    const MappedFile file(output);
    ReadContext context;
    const LasRecords written = readLasRecords(file.bytes(), context);
    EXPECT_THAT(context.formatDetail, HasSubstr("COPC 1.0"));
    EXPECT_EQ(written.recordLength, source->info().format.recordLength());
    EXPECT_EQ(sortedRecords(written.bytes, written.recordLength),
              sortedRecords(expected, written.recordLength));
}

TEST(IndexCommandTest, ScansThatAreNotLasOfDifferentSizesMergeIntoOneFile) {
    // Each got its own grid from its own extent, so the merge refused them.
    const test::TempDir folder;
    const auto small = folder.write("small.xyz", "0.125 0.25 0.5\n1 0.75 0.375\n");
    const auto large = folder.write("large.xyz", "1000.5 2000.25 10\n9000.75 -3000.5 20\n");
    const std::filesystem::path output = folder / "both.copc.laz";
    const test::CommandResult result =
        runSubscan({"index", small.string(), large.string(), "-o", output.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, StartsWith(output.string() + ": 4 points"));
    EXPECT_TRUE(result.err.empty()) << result.err;
}

TEST(IndexCommandTest, TheOutputMustBeACopcFileAndNotAnInput) {
    const test::TempDir folder;
    const std::filesystem::path input = lasInput(folder);
    const test::CommandResult named =
        runSubscan({"index", input.string(), "-o", (folder / "out.laz").string()});
    EXPECT_EQ(named.exitCode, 1);
    EXPECT_EQ(named.err, "subscan: " + (folder / "out.laz").string() +
                             ": the output of index is a COPC file: name it *.copc.laz\n");

    const std::filesystem::path copc = folder / "in.copc.laz";
    std::filesystem::copy_file(input, copc);
    const test::CommandResult over = runSubscan({"index", copc.string(), "-o", copc.string()});
    EXPECT_EQ(over.exitCode, 1);
    EXPECT_EQ(over.err,
              "subscan: " + copc.string() + ": refusing to write the index over its input\n");
    EXPECT_EQ(test::folderEntries(folder.path()),
              (std::vector<std::string>{"in.copc.laz", "input.las"}));
}

TEST(IndexCommandTest, MissingAndTruncatedInputsLeaveNothing) {
    const test::TempDir folder;
    const std::filesystem::path output = folder / "out.copc.laz";
    const test::CommandResult missing =
        runSubscan({"index", (folder / "absent.las").string(), "-o", output.string()});
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_THAT(missing.err, StartsWith("subscan: " + (folder / "absent.las").string()));
    EXPECT_EQ(test::lineCount(missing.err), 1u) << missing.err;

    const std::filesystem::path input = lasInput(folder);
    const std::string bytes = test::fileBytes(input);
    const std::filesystem::path truncated =
        folder.write("truncated.las", bytes.substr(0, bytes.size() - 100));
    std::filesystem::remove(input);
    const test::CommandResult cut =
        runSubscan({"index", truncated.string(), "-o", output.string()});
    EXPECT_EQ(cut.exitCode, 1);
    EXPECT_THAT(cut.err, StartsWith("subscan: " + truncated.string()));
    EXPECT_EQ(test::lineCount(cut.err), 1u) << cut.err;
    EXPECT_EQ(test::folderEntries(folder.path()), (std::vector<std::string>{"truncated.las"}));
}

TEST(IndexCommandTest, AFullDiskIsOneSentenceAndLeavesNothing) {
    const test::TempDir folder;
    const std::filesystem::path output = folder / "out.copc.laz";
    // A file-size limit of 4 KiB (bash's ulimit -f counts 1024-byte blocks): the index of a
    // sphere's 40,000 points (hundreds of KB) fails past it with EFBIG, as on a full disk, while
    // the error sentence still fits the captured stderr, which the limit binds too. SIGXFSZ,
    // which would kill the process, is ignored (an ignored signal stays ignored across exec).
    const test::CommandResult result = test::runProgram(
        "/bin/bash", {"-c", "ulimit -f 4 && trap '' XFSZ && exec \"$0\" index \"$1\" -o \"$2\"",
                      test::subscanExecutable(), "synthetic:sphere?points=40000", output.string()});
    EXPECT_EQ(result.exitCode, 1) << result.err;
    EXPECT_THAT(result.err, HasSubstr("is the disk full?"));
    EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
    EXPECT_TRUE(std::filesystem::is_empty(folder.path()));
}

TEST(IndexCommandTest, CtrlCStopsItAndLeavesNothing) {
    const test::TempDir folder;
    const std::filesystem::path output = folder / "out.copc.laz";
    // A virtual scan of a million points takes over a second to make: the interrupt comes while
    // the scan is made, and the indexer stops at its first step. The exit status is the shell's
    // for a command the signal ended (it was 1, as for a bad input).
    for (const auto& [signal, status] : {std::pair{"INT", 130}, std::pair{"TERM", 143}}) {
        const test::CommandResult result = test::runProgram(
            "/bin/bash",
            {"-c",
             "\"$0\" index 'synthetic:outdoor-station?points=1000000' -o \"$1\" --tmp \"$2\" & "
             "sleep 0.3; kill -$3 $!; wait $!",
             test::subscanExecutable(), output.string(), folder.path().string(), signal});
        EXPECT_EQ(result.exitCode, status) << signal << result.err;
        EXPECT_EQ(result.err,
                  "subscan: " + output.string() + ": interrupted; no output was written\n");
        EXPECT_TRUE(std::filesystem::is_empty(folder.path()));
    }
}

}  // namespace
}  // namespace subscan
