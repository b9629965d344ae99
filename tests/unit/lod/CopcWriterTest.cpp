#include "lod/CopcWriter.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "io/laz/Copc.h"
#include "io/laz/LazEncoder.h"
#include "support/Las14Records.h"
#include "support/MemoryRecordSource.h"
#include "support/PointRecordTestSupport.h"
#include "support/TestSupport.h"

namespace subscan::lod {
namespace {

using test::sortedRecords;

/// Records of `format` whose positions lie on a 40 x 40 m waving terrain (at millimetres) and
/// whose other fields are the LAZ tests' random ones (every field changing, runs of constant
/// fields, values at their limits).
std::vector<std::byte> terrainWithAttributes(const PointRecordFormat& format, std::size_t count,
                                             std::uint32_t seed) {
    test::Las14RecordOptions options;
    options.pointFormat = format.pointFormat;
    options.extraBytes = format.extraBytes;
    options.seed = seed;
    std::vector<std::byte> records = test::randomLas14Records(options, count);
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> along(0.0, 40.0);
    const std::size_t length = format.recordLength();
    for (std::size_t i = 0; i < count; ++i) {
        const double x = along(random), y = along(random);
        const std::int32_t stored[3] = {
            static_cast<std::int32_t>(std::lround(x * 1000)),
            static_cast<std::int32_t>(std::lround(y * 1000)),
            static_cast<std::int32_t>(std::lround(2000 * std::sin(x / 5) * std::cos(y / 7)))};
        std::memcpy(records.data() + i * length, stored, sizeof stored);
    }
    return records;
}

const Quantization kMillimetres{glm::dvec3(0.001), glm::dvec3(500000.0, 4000000.0, 100.0)};

struct Written {
    std::filesystem::path path;
    IndexSummary summary;
    std::uint64_t bytes = 0;
};

Written indexToCopc(const test::TempDir& folder, test::MemoryRecordSource& source,
                    std::size_t maxNodePoints) {
    Written written;
    written.path = folder / "out.copc.laz";
    IndexSettings settings;
    settings.temporaryDirectory = folder.path();
    settings.maxNodePoints = maxNodePoints;
    settings.threads = 2;
    const CopcFile file = writeCopc(source, written.path, settings);
    written.summary = file.summary;
    written.bytes = file.bytes;
    return written;
}

class CopcWriterFormats : public testing::TestWithParam<std::tuple<int, std::size_t>> {};

TEST_P(CopcWriterFormats, TheFileHoldsEveryRecordInItsNodeAndReadsBack) {
    const auto [pointFormat, extraBytes] = GetParam();
    const PointRecordFormat format{pointFormat, extraBytes, {}};
    const std::vector<std::byte> input = terrainWithAttributes(format, 20'000, 7);
    test::MemoryRecordSource source(input, format, kMillimetres);
    source.mutableInfo().wkt = "PROJCS[\"test\"]";
    const test::TempDir folder;
    const Written written = indexToCopc(folder, source, 1'000);
    EXPECT_EQ(std::filesystem::file_size(written.path), written.bytes);
    // Only the output is left: no partial file, no temporary folder.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(folder.path()),
                            std::filesystem::directory_iterator()),
              1);

    const MappedFile file(written.path);
    ReadContext context;
    const LasRecords records = readLasRecords(file.bytes(), context);
    EXPECT_EQ(records.pointFormat, pointFormat);
    EXPECT_EQ(records.recordLength, format.recordLength());
    // Every record back, bit for bit (the reader decodes the chunks through the chunk table).
    EXPECT_EQ(sortedRecords(records.bytes, records.recordLength),
              sortedRecords(input, format.recordLength()));
    EXPECT_NE(context.formatDetail.find("COPC 1.0"), std::string::npos) << context.formatDetail;

    // The header: 64-bit count, scale, offset and the bounds of the stored coordinates.
    const std::byte* header = file.bytes().data();
    EXPECT_EQ(loadLittleEndian<std::uint64_t>(header + las::header_field::kPointCount64), 20'000u);
    EXPECT_EQ(loadLittleEndian<double>(header + las::header_field::kOffset), 500000.0);
    EXPECT_EQ(loadLittleEndian<double>(header + las::header_field::kBounds + 8),
              source.info().min.x);
    EXPECT_EQ(loadLittleEndian<double>(header + las::header_field::kBounds + 32),
              source.info().max.z);

    // The info VLR sits right after the header (COPC's rule) and gives the indexer's cube; every
    // node of the hierarchy holds the points of its voxel.
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(header + las::kHeaderSize14 +
                                                        las::kVlrUserIdOffset)),
              "copc");
    const laz::CopcInfo info =
        laz::parseCopcInfo(file.bytes().subspan(las::kHeaderSize14 + las::kVlrHeaderSize, 160));
    EXPECT_EQ(info.center, written.summary.cube.center);
    EXPECT_EQ(info.halfSize, written.summary.cube.halfSize);
    EXPECT_EQ(info.rootSpacing, written.summary.cube.rootSpacing);
    const std::vector<laz::CopcNode> nodes = laz::readCopcHierarchy(file.bytes(), info);
    std::uint64_t points = 0;
    const laz::LazLayout layout = laz::layeredLazLayout(pointFormat, format.recordLength());
    for (const laz::CopcNode& node : nodes) {
        points += node.chunk.pointCount;
        std::vector<std::byte> decoded(node.chunk.pointCount * format.recordLength());
        laz::decodeChunk(file.bytes().subspan(node.chunk.offset, node.chunk.byteSize),
                         node.chunk.pointCount, layout, decoded.data());
        for (std::size_t i = 0; i < node.chunk.pointCount; ++i) {
            std::int32_t stored[3];
            std::memcpy(stored, decoded.data() + i * format.recordLength(), sizeof stored);
            const glm::dvec3 p = glm::dvec3(stored[0], stored[1], stored[2]) * kMillimetres.scale +
                                 kMillimetres.offset;
            const laz::VoxelKey at = nodeKeyAt(written.summary.cube, p, node.key.level);
            ASSERT_EQ(std::tie(at.x, at.y, at.z), std::tie(node.key.x, node.key.y, node.key.z));
        }
    }
    EXPECT_EQ(points, 20'000u);
    EXPECT_EQ(nodes.size(), written.summary.nodes());
}

INSTANTIATE_TEST_SUITE_P(PointFormats, CopcWriterFormats,
                         testing::Values(std::make_tuple(6, 0), std::make_tuple(7, 3),
                                         std::make_tuple(8, 12)));

TEST(CopcWriterTest, AWriterLeftUnfinishedLeavesNoFile) {
    const test::TempDir folder;
    const PointRecordFormat format{};
    const std::vector<std::byte> input = terrainWithAttributes(format, 100, 3);
    test::MemoryRecordSource source(input, format, kMillimetres);
    {
        CopcWriter writer(folder / "out.copc.laz", source.info(),
                          octreeCubeFor(source.info().min, source.info().max));
        writer.writeNode({0, 0, 0, 0}, input, 100);
    }
    EXPECT_TRUE(std::filesystem::is_empty(folder.path()));
}

TEST(CopcWriterTest, AFolderThatCannotHoldTheFileIsOneSentence) {
    const PointRecordSourceInfo info;
    const std::string message = test::errorMessage([&] {
        CopcWriter writer("/nonexistent-folder/out.copc.laz", info, octreeCubeFor({}, {1, 1, 1}));
    });
    EXPECT_EQ(message.rfind("/nonexistent-folder/out.copc.laz: cannot create a file beside it", 0),
              0u)
        << message;
}

}  // namespace
}  // namespace subscan::lod
