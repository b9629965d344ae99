// The point record sources on the real scans of the shared folder: LAS records converted field
// by field, LAZ and COPC decoded chunk by chunk to the same records, reading in pieces, and the
// memory a large file takes when read in pieces.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include <sys/resource.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/LasReader.h"
#include "io/PointRecordSource.h"
#include "io/ReadContext.h"
#include "io/RecordSourceSupport.h"
#include "support/PointRecordTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::Las14Fields;
using test::loadRecordField;
using test::readAllRecords;
using test::recordFields;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::IsEmpty;
using ::testing::StartsWith;

LasRecords rawRecords(const std::filesystem::path& path) {
    const std::string file = test::fileBytes(path);
    ReadContext context;
    return readLasRecords(test::asBytes(file), context);
}

TEST(PointRecordSourceDataTest, AutzenLasBecomesFormat7WithEveryOriginalField) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto source = openPointRecordSource(data / "autzen_trim.las", 1);
    const PointRecordSourceInfo& info = source->info();
    const LasRecords raw = rawRecords(data / "autzen_trim.las");
    ASSERT_EQ(raw.pointFormat, 3);
    ASSERT_EQ(info.pointCount, raw.size());
    ASSERT_EQ(info.format.pointFormat, 7);
    EXPECT_EQ(info.format.extraBytes, 0u);
    EXPECT_EQ(info.quantization.scale, glm::dvec3(0.01));
    EXPECT_EQ(info.quantization.offset, glm::dvec3(0.0));
    EXPECT_THAT(info.wkt, StartsWith("PROJCS[\"NAD_1983_HARN_Lambert_Conformal_Conic\""));
    EXPECT_THAT(info.warnings, IsEmpty());
    const std::vector<std::byte> records = readAllRecords(*source, 10000);
    ASSERT_EQ(records.size(), raw.size() * 36);
    // Format 3 (R15 table 10): the legacy core, GPS time at 20, RGB at 28.
    std::size_t different = 0;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        const std::byte* p = raw.bytes.data() + i * raw.recordLength;
        Las14Fields expected;
        for (int axis = 0; axis < 3; ++axis) {
            expected.xyz[axis] = loadRecordField<std::int32_t>(p + 4 * axis);
        }
        expected.intensity = loadRecordField<std::uint16_t>(p + 12);
        const auto returns = std::to_integer<int>(p[14]);
        expected.returnNumber = returns & 7;
        expected.numberOfReturns = (returns >> 3) & 7;
        expected.scanDirection = (returns >> 6) & 1;
        expected.edgeOfFlightLine = returns >> 7;
        const auto classification = std::to_integer<int>(p[15]);
        expected.classification = classification & 31;
        expected.classificationFlags = classification >> 5;
        expected.scanAngle =
            static_cast<std::int16_t>(std::lround(loadRecordField<std::int8_t>(p + 16) / 0.006));
        expected.userData = std::to_integer<int>(p[17]);
        expected.pointSourceId = loadRecordField<std::uint16_t>(p + 18);
        expected.gpsTime = loadRecordField<double>(p + 20);
        for (int c = 0; c < 3; ++c) {
            expected.rgb[c] = loadRecordField<std::uint16_t>(p + 28 + 2 * c);
        }
        const Las14Fields actual = recordFields(records, info.format, i);
        if (actual != expected && different++ < 3) {
            ADD_FAILURE() << "record " << i << " differs";
        }
    }
    EXPECT_EQ(different, 0u);
}

TEST(PointRecordSourceDataTest, AutzenLazGivesTheRecordsOfTheLasFileOnAnyNumberOfThreads) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto las = openPointRecordSource(data / "autzen_trim.las", 1);
    const std::vector<std::byte> expected = readAllRecords(*las, 1 << 20);
    for (const unsigned threads : {1u, 2u, 5u, 0u}) {
        const auto laz = openPointRecordSource(data / "autzen_trim.laz", threads);
        EXPECT_EQ(laz->info().format, las->info().format);
        EXPECT_EQ(laz->info().quantization, las->info().quantization);
        EXPECT_EQ(laz->info().wkt, las->info().wkt);
        EXPECT_TRUE(readAllRecords(*laz, 30000) == expected) << threads << " threads";
    }
}

TEST(PointRecordSourceDataTest, LazPiecesAndRewindGiveTheSameRecordsAsOneRead) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // 110,000 points in chunks of 50,000: pieces of 7 and 1000 straddle the chunks' seams.
    const auto laz = openPointRecordSource(data / "autzen_trim.laz", 2);
    const std::vector<std::byte> whole = readAllRecords(*laz, laz->info().pointCount);
    for (const std::size_t piece : {1, 7, 1000}) {
        laz->rewind();
        EXPECT_TRUE(readAllRecords(*laz, piece) == whole) << "pieces of " << piece;
    }
    // Rewinding halfway, while chunks are decoding ahead on other threads.
    laz->rewind();
    std::vector<std::byte> some;
    laz->read(some, 60000);
    laz->rewind();
    EXPECT_TRUE(readAllRecords(*laz, 50000) == whole);
}

TEST(PointRecordSourceDataTest, Las14Format7RecordsPassUnchanged) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto source = openPointRecordSource(data / "autzen_trim_las14_pf7.las", 1);
    const LasRecords raw = rawRecords(data / "autzen_trim_las14_pf7.las");
    ASSERT_EQ(raw.pointFormat, 7);
    EXPECT_FALSE(source->info().wkt.empty());
    EXPECT_TRUE(readAllRecords(*source, 777) == raw.bytes);
}

/// A record of format 6 with X, Y and Z moved onto another grid by whole steps, as bytes.
std::vector<std::vector<std::byte>> recordsOnGrid(PointRecordSource& source,
                                                  const glm::dvec3& offset) {
    const PointRecordSourceInfo& info = source.info();
    const std::vector<std::byte> records = readAllRecords(source, 100000);
    const std::size_t length = info.format.recordLength();
    std::vector<std::vector<std::byte>> moved;
    for (std::size_t i = 0; i < records.size() / length; ++i) {
        std::vector<std::byte> record(
            records.begin() + static_cast<std::ptrdiff_t>(i * length),
            records.begin() + static_cast<std::ptrdiff_t>((i + 1) * length));
        for (int axis = 0; axis < 3; ++axis) {
            const double steps =
                (info.quantization.offset[axis] - offset[axis]) / info.quantization.scale[axis];
            const auto stored = loadRecordField<std::int32_t>(record.data() + 4 * axis) +
                                static_cast<std::int32_t>(std::lround(steps));
            std::memcpy(record.data() + 4 * axis, &stored, 4);
        }
        moved.push_back(std::move(record));
    }
    std::sort(moved.begin(), moved.end());
    return moved;
}

TEST(PointRecordSourceDataTest, LoneStarLazAndCopcHoldTheSameRecords) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto laz = openPointRecordSource(data / "lone_star.laz", 2);
    const auto copc = openPointRecordSource(data / "lone_star.copc.laz", 2);
    ASSERT_EQ(laz->info().pointCount, 518862u);
    ASSERT_EQ(copc->info().pointCount, laz->info().pointCount);
    ASSERT_EQ(laz->info().format.pointFormat, 6);  // from format 1
    ASSERT_EQ(copc->info().format.pointFormat, 6);
    ASSERT_EQ(laz->info().quantization.scale, copc->info().quantization.scale);
    // The files' offsets differ by whole steps of their common scale: on one grid the records,
    // every byte of them, are the same multiset (the octree reorders them).
    const glm::dvec3 grid = laz->info().quantization.offset;
    const auto a = recordsOnGrid(*laz, grid);
    const auto b = recordsOnGrid(*copc, grid);
    ASSERT_EQ(a.size(), b.size());
    std::size_t different = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i] != b[i] && different++ < 3) {
            const Las14Fields p = test::decodeLas14(a[i].data(), 6, 0);
            const Las14Fields q = test::decodeLas14(b[i].data(), 6, 0);
            ADD_FAILURE() << "sorted record " << i << ": " << p.xyz[0] << " " << p.xyz[1] << " "
                          << p.xyz[2] << " vs " << q.xyz[0] << " " << q.xyz[1] << " " << q.xyz[2];
        }
    }
    EXPECT_EQ(different, 0u);
}

TEST(PointRecordSourceDataTest, AnEptDatasetNamedByItsFolderGivesTheRecordsOfItsSource) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // PDAL's lone star EPT was built from lone_star.laz: its tiles are that file's records on
    // the dataset's grid (classification, GPS time and returns included), which converting
    // them to a cloud and back lost.
    const auto laz = openPointRecordSource(data / "lone_star.laz", 2);
    const auto ept = openPointRecordSource(data / "ept" / "lone-star-laszip", 2);
    const PointRecordSourceInfo& info = ept->info();
    EXPECT_EQ(info.name, (data / "ept" / "lone-star-laszip").string());
    ASSERT_EQ(info.pointCount, laz->info().pointCount);
    ASSERT_EQ(info.format.pointFormat, 6);
    ASSERT_EQ(info.quantization.scale, laz->info().quantization.scale);
    // The tiles hold GeoTIFF keys only; ept.json's srs gives the WKT, so nothing is lost.
    EXPECT_THAT(info.wkt, StartsWith("PROJCS[\"NAD83 / UTM zone 12N\""));
    EXPECT_THAT(info.warnings, IsEmpty());
    // Entwine adds its OriginId (the source file's number) to every record as extra bytes.
    EXPECT_EQ(info.format.extraBytes, 4u);
    EXPECT_EQ(extraBytesFieldNames(info.format.extraBytesDescriptors), "OriginId");
    const glm::dvec3 grid = laz->info().quantization.offset;
    std::vector<std::vector<std::byte>> tiles = recordsOnGrid(*ept, grid);
    for (std::vector<std::byte>& record : tiles) {
        record.resize(30);
    }
    std::sort(tiles.begin(), tiles.end());
    EXPECT_TRUE(recordsOnGrid(*laz, grid) == tiles);
}

TEST(PointRecordSourceDataTest, LazAndCopcMergeOntoOneGridWithTheCopcCoordinateSystem) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    std::vector<std::unique_ptr<PointRecordSource>> sources;
    sources.push_back(openPointRecordSource(data / "lone_star.laz", 2));
    sources.push_back(openPointRecordSource(data / "lone_star.copc.laz", 2));
    const auto merged = mergePointRecordSources(std::move(sources));
    const PointRecordSourceInfo& info = merged->info();
    EXPECT_EQ(info.pointCount, 2 * 518862u);
    EXPECT_THAT(info.wkt, StartsWith("GEOCCS["));  // lone_star.laz has only GeoTIFF keys
    EXPECT_THAT(info.warnings, Contains(AllOf(HasSubstr("lone_star.laz"), HasSubstr("GeoTIFF"))));
    const std::vector<std::byte> records = readAllRecords(*merged, 65536);
    ASSERT_EQ(records.size(), info.pointCount * 30);
    // The second half is the COPC file moved onto the first file's grid: sorted, the halves
    // are the same records.
    std::vector<std::vector<std::byte>> first, second;
    for (std::size_t i = 0; i < info.pointCount; ++i) {
        const auto begin = records.begin() + static_cast<std::ptrdiff_t>(30 * i);
        (i < 518862 ? first : second).emplace_back(begin, begin + 30);
    }
    std::sort(first.begin(), first.end());
    std::sort(second.begin(), second.end());
    EXPECT_TRUE(first == second);
}

TEST(PointRecordSourceDataTest, DamagedLazFilesAreOneSentenceNamingFileAndChunk) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const test::TempDir dir;
    const std::string laz = test::fileBytes(data / "autzen_trim.laz");
    // Cut before the chunk table: its offset now lies outside the file.
    const auto cut = dir.write("cut.laz", laz.substr(0, laz.size() / 2));
    EXPECT_THAT(test::errorMessage([&] { openPointRecordSource(cut, 2); }),
                AllOf(HasSubstr("cut.laz"), HasSubstr("chunk table offset")));
    // Garbage inside the second chunk: found when that chunk is read.
    std::string damaged = laz;
    std::fill(damaged.begin() + 300000, damaged.begin() + 300400, '\xFF');
    const auto path = dir.write("damaged.laz", damaged);
    const auto source = openPointRecordSource(path, 2);
    const std::string message = test::errorMessage([&] { readAllRecords(*source, 1000); });
    EXPECT_THAT(message, AllOf(HasSubstr("damaged.laz"), HasSubstr("LAZ chunk")));
}

long peakResidentKilobytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss;
}

TEST(PointRecordSourceDataTest, ALargeLasFileIsReadInMemoryFarBelowItsSize) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // 60 copies of Autzen's records behind its own header: 6.6 M points, 224 MB, written in
    // pieces so that the test itself never holds it.
    const test::TempDir dir;
    const std::string las = test::fileBytes(data / "autzen_trim.las");
    const LasRecords raw = rawRecords(data / "autzen_trim.las");
    const std::size_t pointData = las.size() - raw.bytes.size();
    std::string header = las.substr(0, pointData);
    const std::uint32_t copies = 60;
    const auto count = static_cast<std::uint32_t>(raw.size() * copies);
    std::memcpy(header.data() + 107, &count, 4);  // the legacy point count
    const std::filesystem::path path = dir / "large.las";
    {
        std::ofstream out(path, std::ios::binary);
        out.write(header.data(), static_cast<std::streamsize>(header.size()));
        for (std::uint32_t i = 0; i < copies; ++i) {
            out.write(reinterpret_cast<const char*>(raw.bytes.data()),
                      static_cast<std::streamsize>(raw.bytes.size()));
        }
    }
    const auto fileSize = std::filesystem::file_size(path);
    const long before = peakResidentKilobytes();
    const auto source = openPointRecordSource(path, 1);
    std::vector<std::byte> piece;
    std::uint64_t points = 0;
    while (true) {
        piece.clear();
        const std::size_t got = source->read(piece, 1 << 16);
        if (got == 0) {
            break;
        }
        points += got;
    }
    const long grown = peakResidentKilobytes() - before;
    EXPECT_EQ(points, count);
    // A piece of 65,536 records is 2.4 MB; the reader's block as much again. A quarter of the
    // file (56 MB) leaves room for the allocator and the page cache's accounting, and is far
    // below what reading the file whole would add (224 MB).
    EXPECT_LT(grown * 1024, static_cast<long>(fileSize / 4))
        << "peak resident memory grew by " << grown << " kB reading a " << fileSize / 1024
        << " kB file";
}

}  // namespace
}  // namespace subscan
