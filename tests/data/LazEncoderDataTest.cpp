// The LAZ encoder against real files. lone_star.copc.laz was written by laz-perf (its laszip VLR
// says "lazperf variant"), an independent port of LASzip's layered (v3) coder: if our encoder
// mirrors that coder, decoding each of its chunks and encoding the points again gives back the
// file's bytes, chunk table and laszip VLR included. The few choices the format leaves an
// encoder (the rounding of a GPS time's multiple, times compared as bits or as doubles; see
// ItemEncoding.cpp and LayeredItemEncoders.cpp) are made as LASzip and laz-perf make them but
// for NaN, -0.0 and one float quotient, so any difference here is a bug.
// autzen_trim_las14_pf7.las (point format 7, real RGB) goes through our writer and decoder
// unchanged.

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LasReader.h"
#include "io/LazWriter.h"
#include "io/ReadContext.h"
#include "io/laz/Copc.h"
#include "io/laz/LazDecoder.h"
#include "io/laz/LazEncoder.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

namespace field = las::header_field;

std::span<const std::byte> bytesOf(const std::string& file) {
    return test::asBytes(file);
}

/// The payload of the first VLR of `user`, or an empty span.
std::span<const std::byte> vlrPayload(const std::string& file, std::string_view user) {
    const std::size_t payload = test::lasVlrPayloadOffset(file, user);
    if (payload == 0) {
        return {};
    }
    return bytesOf(file).subspan(
        payload, loadLittleEndian<std::uint16_t>(file.data() + payload - las::kVlrHeaderSize +
                                                 las::kVlrLengthOffset));
}

std::string describeFirstDifference(std::span<const std::byte> expected,
                                    std::span<const std::byte> actual) {
    const auto [e, a] =
        std::mismatch(expected.begin(), expected.end(), actual.begin(), actual.end());
    return "sizes " + std::to_string(expected.size()) + " and " + std::to_string(actual.size()) +
           ", first difference at byte " + std::to_string(e - expected.begin());
}

/// A LAZ file whose points are in layered chunks, and who wrote it.
struct LayeredFile {
    const char* testName;
    const char* name;
    const char* origin;  // nullptr: the shared data folder has it
};

void PrintTo(const LayeredFile& file, std::ostream* out) {
    *out << file.name;
}

class LazEncoderReencodeTest : public ::testing::TestWithParam<LayeredFile> {};

TEST_P(LazEncoderReencodeTest, EveryChunkReencodesToTheSameBytes) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const LayeredFile& which = GetParam();
    const std::filesystem::path path = data / which.name;
    if (which.origin != nullptr && !std::filesystem::exists(path)) {
        GTEST_SKIP() << which.name << " is not in the data folder (it is " << which.origin << ")";
    }
    const std::string file = test::fileBytes(path);
    ASSERT_GT(file.size(), las::kHeaderSize14) << path;
    const int pointFormat =
        static_cast<int>(static_cast<unsigned char>(file[field::kPointFormat])) & 0x3F;
    const auto recordLength = loadLittleEndian<std::uint16_t>(file.data() + field::kRecordLength);
    const std::span<const std::byte> laszip = vlrPayload(file, "laszip encoded");
    const laz::LazLayout layout = laz::parseLaszipRecord(laszip, pointFormat, recordLength);
    ASSERT_EQ(layout.compressor, laz::kCompressorLayeredChunked);

    // The laszip VLR we write for these records (with the file's chunk size) is the file's.
    laz::LazLayout ours = laz::layeredLazLayout(pointFormat, recordLength);
    ours.chunkSize = layout.chunkSize;
    const std::vector<std::byte> ourVlr = laz::laszipRecordPayload(ours);
    EXPECT_TRUE(std::ranges::equal(ourVlr, laszip)) << describeFirstDifference(laszip, ourVlr);

    const auto pointData = loadLittleEndian<std::uint32_t>(file.data() + field::kPointDataOffset);
    const auto pointCount = loadLittleEndian<std::uint64_t>(file.data() + field::kPointCount64);
    const std::vector<laz::Chunk> chunks =
        laz::readChunkTable(bytesOf(file), pointData, layout, pointCount);
    laz::ChunkEncoder encoder(layout);
    std::size_t identical = 0;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        const laz::Chunk& chunk = chunks[i];
        const std::span<const std::byte> original =
            bytesOf(file).subspan(chunk.offset, chunk.byteSize);
        std::vector<std::byte> records(chunk.pointCount * layout.recordLength);
        laz::decodeChunk(original, chunk.pointCount, layout, records.data());
        const std::vector<std::byte> again = encoder.encode(records);
        if (std::ranges::equal(again, original)) {
            ++identical;
        } else {
            ADD_FAILURE() << "chunk " << i + 1 << " of " << chunks.size() << " ("
                          << chunk.pointCount << " points) encodes to other bytes: "
                          << describeFirstDifference(original, again);
        }
    }
    EXPECT_EQ(identical, chunks.size());

    // The chunk table after the chunks, too.
    const bool variable = layout.chunkSize == laz::kVariableChunkSize;
    const std::vector<std::byte> table = laz::encodeChunkTable(chunks, variable);
    const auto tableOffset = loadLittleEndian<std::uint64_t>(file.data() + pointData);
    ASSERT_LE(tableOffset + table.size(), file.size());
    const std::span<const std::byte> fileTable = bytesOf(file).subspan(tableOffset, table.size());
    EXPECT_TRUE(std::ranges::equal(table, fileTable)) << describeFirstDifference(fileTable, table);
}

// lone_star.copc.laz is in the shared folder: point format 6, 15 COPC nodes of 212 to 126,731
// points, written by laz-perf (PDAL's COPC writer). Only x, y, z and intensity vary within its
// chunks. The others, checked when present, make every field vary: PDAL's test files
// test/data/laz/las_with_several_extra_byte_bloc.laz (point format 8 with 3 extra bytes, GPS
// time, NIR; written by LASzip 3.4 r3 itself, in 14 chunks of 50,000 points),
// test/data/copc/1.2-with-color.copc.laz (point format 7, 65 COPC nodes, laz-perf) and
// test/data/tindex/autzen_clip_native.copc.laz (point format 7, laz-perf, scanner channels 0
// and 1 alternating: RGB's contexts switch with them).
INSTANTIATE_TEST_SUITE_P(
    WrittenByOthers, LazEncoderReencodeTest,
    ::testing::Values(LayeredFile{"LoneStarCopc", "lone_star.copc.laz", nullptr},
                      LayeredFile{"SeveralExtraByteBlocks", "las_with_several_extra_byte_bloc.laz",
                                  "PDAL's test/data/laz/las_with_several_extra_byte_bloc.laz"},
                      LayeredFile{"WithColorCopc", "1.2-with-color.copc.laz",
                                  "PDAL's test/data/copc/1.2-with-color.copc.laz"},
                      LayeredFile{"TwoScannerChannelsCopc", "autzen_clip_native.copc.laz",
                                  "PDAL's test/data/tindex/autzen_clip_native.copc.laz"}),
    [](const ::testing::TestParamInfo<LayeredFile>& file) { return file.param.testName; });

TEST(LazEncoderDataTest, LoneStarCopcIsManyNodesOfVariableSize) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // What makes the re-encoding above a check of variable chunks: the COPC nodes, each its own
    // chunk of its own size.
    const std::string file = test::fileBytes(data / "lone_star.copc.laz");
    const std::vector<laz::CopcNode> nodes =
        laz::readCopcHierarchy(bytesOf(file), laz::parseCopcInfo(vlrPayload(file, "copc")));
    ASSERT_EQ(nodes.size(), 15u);
    std::uint64_t points = 0;
    std::uint64_t smallest = nodes[0].chunk.pointCount;
    std::uint64_t largest = 0;
    for (const laz::CopcNode& node : nodes) {
        points += node.chunk.pointCount;
        smallest = std::min(smallest, node.chunk.pointCount);
        largest = std::max(largest, node.chunk.pointCount);
    }
    EXPECT_EQ(points, 518862u);
    EXPECT_EQ(smallest, 212u);
    EXPECT_EQ(largest, 126731u);
}

TEST(LazEncoderDataTest, AutzenFormat7RoundTripsThroughVariableChunks) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const std::string las = test::fileBytes(data / "autzen_trim_las14_pf7.las");
    ASSERT_FALSE(las.empty());
    ReadContext context;
    const LasRecords records = readLasRecords(bytesOf(las), context);
    ASSERT_EQ(records.pointFormat, 7);
    ASSERT_EQ(records.size(), 110000u);

    LazFileContents contents;
    contents.header.assign(bytesOf(las).begin(), bytesOf(las).begin() + las::kHeaderSize14);
    contents.records = records.bytes;
    // Chunks of one point, a typical LASzip chunk, an odd one and the rest.
    contents.chunkPointCounts = {1, 50000, 7, 110000 - 50008};
    const std::vector<std::byte> laz = encodeLazFile(contents);
    const LasRecords decoded = readLasRecords(laz, context);
    ASSERT_EQ(decoded.pointFormat, 7);
    ASSERT_EQ(decoded.size(), records.size());
    EXPECT_TRUE(decoded.bytes == records.bytes)
        << describeFirstDifference(records.bytes, decoded.bytes);
    // Real RGB and coordinates compress: LASzip makes airborne scans 5-10 times smaller; a coder
    // that codes every field in full would not reach half.
    EXPECT_LT(laz.size(), las.size() / 2);
}

}  // namespace
}  // namespace subscan
