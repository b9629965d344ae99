// Complete LAZ 1.4 files (io/LazWriter.h) read back by the project's LAS reader: the records,
// the header fields the writer sets, the VLRs and EVLRs where the header says, the chunk table;
// and the inputs it refuses.
#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LasReader.h"
#include "io/LazWriter.h"
#include "io/ReadContext.h"
#include "io/laz/LazDecoder.h"
#include "support/Las14Records.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

std::vector<std::byte> payloadOf(std::string_view text) {
    const auto* bytes = reinterpret_cast<const std::byte*>(text.data());
    return {bytes, bytes + text.size()};
}

/// Format 7 with two extra bytes in chunks of 3, 1 and 40 points, one VLR before the laszip VLR
/// and one EVLR after the chunk table.
struct Format7File {
    std::vector<std::byte> records = test::randomLas14Records({7, 2, true, 21}, 44);
    LazFileContents contents;

    Format7File() {
        contents.header = test::las14Header(7, test::las14RecordLength(7, 2), 44);
        contents.vlrs.push_back({"subscan", 7, "a test VLR", payloadOf("hello")});
        contents.records = records;
        contents.chunkPointCounts = {3, 1, 40};
        contents.extendedVlrs.push_back({"subscan", 8, "a test EVLR", payloadOf("after")});
    }
};

template <class T>
T field(const std::vector<std::byte>& file, std::size_t offset) {
    return loadLittleEndian<T>(file.data() + offset);
}

TEST(LazWriterTest, TheReaderReadsBackTheRecordsAndTheLayout) {
    const Format7File input;
    LazFileLayout layout;
    const std::vector<std::byte> file = encodeLazFile(input.contents, &layout);

    ReadContext context;
    const LasRecords records = readLasRecords(file, context);
    ASSERT_EQ(records.pointFormat, 7);
    ASSERT_EQ(records.recordLength, 38u);
    EXPECT_TRUE(records.bytes == input.records);

    // LAS 1.4 R15 table 3: what the writer set. Point format 7 with the compression bit; two
    // VLRs (ours, then laszip's) between header and points; legacy counts zero for format 7;
    // the EVLR after the chunk table.
    EXPECT_EQ(field<std::uint8_t>(file, 104), 0x87);
    // A format byte that comes with compression bits already (LASzip's 0xC0) gets 0x80 alone.
    Format7File marked;
    marked.contents.header[104] = std::byte{0xC7};
    EXPECT_EQ(field<std::uint8_t>(encodeLazFile(marked.contents), 104), 0x87);
    EXPECT_EQ(field<std::uint32_t>(file, 100), 2u);
    EXPECT_EQ(field<std::uint32_t>(file, 107), 0u);
    EXPECT_EQ(field<std::uint64_t>(file, 247), 44u);
    const auto pointData = field<std::uint32_t>(file, 96);
    const std::size_t laszipVlr = 375 + 54 + 5;
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(file.data()) + 375 + 2), "subscan");
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(file.data()) + laszipVlr + 2),
              "laszip encoded");
    EXPECT_EQ(field<std::uint16_t>(file, laszipVlr + 18), 22204);
    const auto laszipLength = field<std::uint16_t>(file, laszipVlr + 20);
    EXPECT_EQ(pointData, laszipVlr + 54 + laszipLength);
    EXPECT_EQ(field<std::int64_t>(file, pointData),
              static_cast<std::int64_t>(layout.chunkTableOffset));

    EXPECT_EQ(field<std::uint64_t>(file, 235), layout.firstExtendedVlrOffset);
    EXPECT_EQ(field<std::uint32_t>(file, 243), 1u);
    const std::size_t evlr = layout.firstExtendedVlrOffset;
    EXPECT_EQ(field<std::uint16_t>(file, evlr + 18), 8);
    EXPECT_EQ(field<std::uint64_t>(file, evlr + 20), 5u);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(file.data()) + evlr + 60, 5), "after");
    EXPECT_EQ(evlr + las::kEvlrHeaderSize + 5, file.size());

    // The chunk table lists the chunks where the layout says they are.
    const laz::LazLayout lazLayout =
        laz::parseLaszipRecord(std::span(file).subspan(laszipVlr + 54, laszipLength), 7, 38);
    const std::vector<laz::Chunk> table = laz::readChunkTable(file, pointData, lazLayout, 44);
    ASSERT_EQ(table.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(table[i].offset, layout.chunks[i].offset);
        EXPECT_EQ(table[i].byteSize, layout.chunks[i].byteSize);
        EXPECT_EQ(table[i].pointCount, input.contents.chunkPointCounts[i]);
    }
    EXPECT_EQ(table[0].offset, pointData + 8u);

    // And as a scan: 44 points with colour.
    const LoadedScan scan = test::decode(
        std::string_view(reinterpret_cast<const char*>(file.data()), file.size()), "x.laz");
    EXPECT_EQ(scan.cloud.size(), 44u);
    EXPECT_TRUE(scan.cloud.hasColors());
}

TEST(LazWriterTest, WritesTheFileAtomically) {
    const Format7File input;
    const test::TempDir dir;
    const LazFileLayout layout = writeLaz(dir / "points.laz", input.contents);
    const std::string written = test::fileBytes(dir / "points.laz");
    const std::vector<std::byte> expected = encodeLazFile(input.contents);
    EXPECT_EQ(written.size(), expected.size());
    EXPECT_EQ(0, std::memcmp(written.data(), expected.data(), expected.size()));
    EXPECT_EQ(layout.chunks.size(), 3u);
    test::expectUnwritablePathIsAnErrorNamingIt(
        [&](const std::filesystem::path& path) { writeLaz(path, input.contents); }, "x.laz");
}

TEST(LazWriterTest, NoPointsMakeAFileOfNoChunks) {
    LazFileContents contents;
    contents.header = test::las14Header(6, 30, 0);
    const std::vector<std::byte> file = encodeLazFile(contents);
    ReadContext context;
    EXPECT_EQ(readLasRecords(file, context).size(), 0u);
    EXPECT_EQ(field<std::uint64_t>(file, 235), 0u);  // no EVLRs
}

TEST(LazWriterTest, InputsThatDoNotFitAreRefused) {
    const auto errorFor = [](const std::function<void(LazFileContents&)>& change) {
        Format7File input;
        change(input.contents);
        return test::errorMessage([&] { encodeLazFile(input.contents); });
    };
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.header.resize(227); }),
                HasSubstr("375-byte LAS 1.4 header; this one has 227"));
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.header[25] = std::byte{2}; }),
                HasSubstr("LAS 1.2"));
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.header[104] = std::byte{3}; }),
                HasSubstr("not point format 3"));
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.header[247] = std::byte{45}; }),
                HasSubstr("declares 45 points of 38 bytes, but the records have 1672 bytes"));
    EXPECT_THAT(errorFor([](LazFileContents& c) {
                    c.chunkPointCounts = {3, 1, 39};
                }),
                HasSubstr("the chunks hold 43 points in all, but there are 44"));
    EXPECT_THAT(errorFor([](LazFileContents& c) {
                    c.chunkPointCounts = {3, 0, 41};
                }),
                HasSubstr("chunk of 0 points"));
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.vlrs[0].userId = std::string(17, 'u'); }),
                HasSubstr("longer than 16 bytes"));
    EXPECT_THAT(errorFor([](LazFileContents& c) { c.vlrs[0].payload.resize(70000); }),
                HasSubstr("70000 bytes, more than a VLR holds"));
    // An EVLR holds that much.
    Format7File large;
    large.contents.extendedVlrs[0].payload.resize(70000);
    EXPECT_NO_THROW(encodeLazFile(large.contents));
}

}  // namespace
}  // namespace subscan
