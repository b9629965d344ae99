// The point record sources on files the tests write: every LAS point format converted field by
// field, extra bytes and their descriptors, coordinate systems, PLY and text inputs, reading in
// pieces, merging, and bad inputs. Real scans (LAZ, COPC, the size of surveys) are in
// tests/data/PointRecordSourceDataTest.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/Las14Writer.h"
#include "io/LasWriter.h"
#include "io/LazWriter.h"
#include "io/PointRecordSource.h"
#include "io/RecordSourceSupport.h"
#include "support/PointRecordTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::appendBytes;
using test::Las14Fields;
using test::readAllRecords;
using test::recordFields;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

/// Sizes of point formats 0-10 (LAS 1.4 R15, section 2.6).
constexpr std::array<std::size_t, 11> kFormatSizes{20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr std::size_t kWavePacketSize = 29;
constexpr std::size_t kDescriptorSize = 192;

bool hasGpsTime(int format) {
    return format != 0 && format != 2;
}
bool hasRgb(int format) {
    return format == 2 || format == 3 || format == 5 || format == 7 || format == 8 || format == 10;
}
bool hasNir(int format) {
    return format == 8 || format == 10;
}
bool hasWavePacket(int format) {
    return format == 4 || format == 5 || format == 9 || format == 10;
}

struct Vlr {
    std::string user;
    std::uint16_t recordId = 0;
    std::string payload;
};

/// A LAS file built from raw records: header (1.2 or 1.4), VLRs, records, EVLRs.
struct TestLas {
    int versionMinor = 2;
    int pointFormat = 3;
    std::size_t recordLength = 0;  // 0: the format's size
    glm::dvec3 scale{0.01};
    glm::dvec3 offset{0.0};
    std::vector<Vlr> vlrs;
    std::vector<Vlr> evlrs;  // LAS 1.4 only
    std::optional<std::uint64_t> declaredCount;
    std::uint16_t fileSourceId = 0;
    std::uint16_t globalEncoding = 0;
    std::vector<std::string> records;

    std::size_t length() const {
        return recordLength != 0 ? recordLength : kFormatSizes[pointFormat];
    }

    std::string bytes() const {
        const std::size_t headerSize = versionMinor >= 4 ? 375 : versionMinor == 3 ? 235 : 227;
        std::string out = "LASF";
        appendBytes(out, fileSourceId);
        appendBytes(out, globalEncoding);
        out.append(16, '\0');  // GUID
        out.push_back(1);
        out.push_back(static_cast<char>(versionMinor));
        out.append(64, '\0');  // system identifier, generating software
        appendBytes<std::uint16_t>(out, 1);
        appendBytes<std::uint16_t>(out, 2024);
        std::size_t vlrBytes = 0;
        for (const Vlr& vlr : vlrs) {
            vlrBytes += 54 + vlr.payload.size();
        }
        const std::uint64_t count = declaredCount.value_or(records.size());
        appendBytes<std::uint16_t>(out, static_cast<std::uint16_t>(headerSize));
        appendBytes<std::uint32_t>(out, static_cast<std::uint32_t>(headerSize + vlrBytes));
        appendBytes<std::uint32_t>(out, static_cast<std::uint32_t>(vlrs.size()));
        appendBytes<std::uint8_t>(out, static_cast<std::uint8_t>(pointFormat));
        appendBytes<std::uint16_t>(out, static_cast<std::uint16_t>(length()));
        appendBytes<std::uint32_t>(out, pointFormat >= 6 ? 0 : static_cast<std::uint32_t>(count));
        out.append(20, '\0');  // points by return
        for (const glm::dvec3& triple : {scale, offset}) {
            for (int axis = 0; axis < 3; ++axis) {
                appendBytes(out, triple[axis]);
            }
        }
        for (int axis = 0; axis < 3; ++axis) {
            // The stored coordinates' bounds, max before min.
            std::int32_t low = std::numeric_limits<std::int32_t>::max();
            std::int32_t high = std::numeric_limits<std::int32_t>::min();
            for (const std::string& record : records) {
                std::int32_t stored = 0;
                std::memcpy(&stored, record.data() + 4 * axis, 4);
                low = std::min(low, stored);
                high = std::max(high, stored);
            }
            appendBytes(out, records.empty() ? 0.0 : high * scale[axis] + offset[axis]);
            appendBytes(out, records.empty() ? 0.0 : low * scale[axis] + offset[axis]);
        }
        if (versionMinor >= 3) {
            appendBytes<std::uint64_t>(out, 0);  // waveform data
        }
        if (versionMinor >= 4) {
            const std::uint64_t evlrOffset = headerSize + vlrBytes + records.size() * length();
            appendBytes<std::uint64_t>(out, evlrs.empty() ? 0 : evlrOffset);
            appendBytes<std::uint32_t>(out, static_cast<std::uint32_t>(evlrs.size()));
            appendBytes<std::uint64_t>(out, count);
            out.append(15 * 8, '\0');
        }
        for (const Vlr& vlr : vlrs) {
            appendBytes<std::uint16_t>(out, 0);
            out += vlr.user + std::string(16 - vlr.user.size(), '\0');
            appendBytes(out, vlr.recordId);
            appendBytes<std::uint16_t>(out, static_cast<std::uint16_t>(vlr.payload.size()));
            out.append(32, '\0');
            out += vlr.payload;
        }
        for (const std::string& record : records) {
            out += record;
        }
        for (const Vlr& evlr : evlrs) {
            appendBytes<std::uint16_t>(out, 0);
            out += evlr.user + std::string(16 - evlr.user.size(), '\0');
            appendBytes(out, evlr.recordId);
            appendBytes<std::uint64_t>(out, evlr.payload.size());
            out.append(32, '\0');
            out += evlr.payload;
        }
        return out;
    }
};

/// Distinct values for every field of point i, within what `format` can hold.
Las14Fields fieldsOfPoint(int format, int i, std::size_t extraBytes) {
    const bool legacy = format < 6;
    Las14Fields f;
    f.xyz = {1000 + 37 * i, -2000 - 11 * i, 3 * i - 60};
    f.intensity = static_cast<std::uint16_t>(65535 - 1000 * i);
    f.returnNumber = legacy ? i % 8 : i % 16;
    f.numberOfReturns = legacy ? (i / 8) % 8 : (3 * i) % 16;
    f.classificationFlags = legacy ? (i >> 2) & 7 : (i >> 2) & 15;
    f.scannerChannel = legacy ? 0 : i % 4;
    f.scanDirection = i & 1;
    f.edgeOfFlightLine = (i >> 1) & 1;
    f.classification = legacy ? i % 32 : (7 * i) % 256;
    f.userData = (13 * i) % 256;
    f.pointSourceId = static_cast<std::uint16_t>(500 + i);
    f.gpsTime = hasGpsTime(format) ? 123456.789 + 0.001 * i : 0.0;
    if (hasRgb(format)) {
        f.rgb = {static_cast<std::uint16_t>(1000 * i), static_cast<std::uint16_t>(65535 - i),
                 static_cast<std::uint16_t>(257 * i)};
    }
    f.nir = hasNir(format) ? static_cast<std::uint16_t>(40000 + i) : 0;
    for (std::size_t k = 0; k < extraBytes; ++k) {
        f.extraBytes.push_back(static_cast<std::byte>(31 * k + static_cast<std::size_t>(i)));
    }
    return f;
}

/// Whole-degree scan angle ranks worth testing (int8), in turn.
constexpr std::array<std::int8_t, 9> kRanks{-128, -90, -45, -1, 0, 1, 45, 90, 127};
/// Their 1.4 values in 0.006 degree steps, round(rank / 0.006), worked out by hand:
/// 1 / 0.006 = 166.67 -> 167, 45 / 0.006 = 7500, 127 / 0.006 = 21166.67 -> 21167.
constexpr std::array<std::int16_t, 9> kRankSteps{-21333, -15000, -7500, -167, 0,
                                                 167,    7500,   15000, 21167};

/// The raw record of `format` holding `f`: the legacy layout (R15 tables 7-12) or the 1.4 one.
std::string rawRecord(int format, int i, const Las14Fields& f, std::size_t length) {
    std::string r;
    for (const std::int32_t v : f.xyz) {
        appendBytes(r, v);
    }
    appendBytes(r, f.intensity);
    if (format < 6) {
        appendBytes<std::uint8_t>(
            r, static_cast<std::uint8_t>(f.returnNumber | f.numberOfReturns << 3 |
                                         f.scanDirection << 6 | f.edgeOfFlightLine << 7));
        appendBytes<std::uint8_t>(
            r, static_cast<std::uint8_t>(f.classification | f.classificationFlags << 5));
        appendBytes<std::int8_t>(r, kRanks[static_cast<std::size_t>(i) % kRanks.size()]);
        appendBytes<std::uint8_t>(r, static_cast<std::uint8_t>(f.userData));
        appendBytes(r, f.pointSourceId);
        if (hasGpsTime(format)) {
            appendBytes(r, f.gpsTime);
        }
    } else {
        appendBytes<std::uint8_t>(
            r, static_cast<std::uint8_t>(f.returnNumber | f.numberOfReturns << 4));
        appendBytes<std::uint8_t>(
            r, static_cast<std::uint8_t>(f.classificationFlags | f.scannerChannel << 4 |
                                         f.scanDirection << 6 | f.edgeOfFlightLine << 7));
        appendBytes<std::uint8_t>(r, static_cast<std::uint8_t>(f.classification));
        appendBytes<std::uint8_t>(r, static_cast<std::uint8_t>(f.userData));
        appendBytes<std::int16_t>(r, static_cast<std::int16_t>(1234 * i - 20000));
        appendBytes(r, f.pointSourceId);
        appendBytes(r, f.gpsTime);
    }
    if (hasRgb(format)) {
        for (const std::uint16_t c : f.rgb) {
            appendBytes(r, c);
        }
    }
    if (hasNir(format)) {
        appendBytes(r, f.nir);
    }
    if (hasWavePacket(format)) {
        r.append(kWavePacketSize, '\xA5');
    }
    EXPECT_EQ(r.size(), kFormatSizes[format]);
    for (const std::byte b : f.extraBytes) {
        r.push_back(static_cast<char>(b));
    }
    EXPECT_EQ(r.size(), length);
    return r;
}

/// What the record of point i must read as, once in format 6, 7 or 8.
Las14Fields expectedFields(int format, int i, std::size_t extraBytes) {
    Las14Fields f = fieldsOfPoint(format, i, extraBytes);
    f.scanAngle = format < 6 ? kRankSteps[static_cast<std::size_t>(i) % kRankSteps.size()]
                             : static_cast<std::int16_t>(1234 * i - 20000);
    return f;
}

TestLas lasWithEveryField(int format, std::size_t extraBytes, int points = 40) {
    TestLas las;
    las.versionMinor = format >= 6 ? 4 : format >= 4 ? 3 : 2;
    las.pointFormat = format;
    las.recordLength = kFormatSizes[format] + extraBytes;
    for (int i = 0; i < points; ++i) {
        las.records.push_back(
            rawRecord(format, i, fieldsOfPoint(format, i, extraBytes), las.recordLength));
    }
    return las;
}

std::unique_ptr<PointRecordSource> open(const std::filesystem::path& path, unsigned threads = 1) {
    return openPointRecordSource(path, threads);
}

std::string openError(const std::filesystem::path& path) {
    return test::errorMessage([&] { open(path); });
}

int expectedOutputFormat(int format) {
    return hasNir(format) ? 8 : hasRgb(format) ? 7 : 6;
}

TEST(PointRecordSourceTest, EveryLasPointFormatBecomesFormat6To8FieldByField) {
    const test::TempDir dir;
    for (int format = 0; format <= 10; ++format) {
        for (const std::size_t extraBytes : {std::size_t{0}, std::size_t{5}}) {
            SCOPED_TRACE(::testing::Message()
                         << "format " << format << ", " << extraBytes << " extra bytes");
            const TestLas las = lasWithEveryField(format, extraBytes);
            const auto path = dir.write("f" + std::to_string(format) + ".las", las.bytes());
            const auto source = open(path);
            const PointRecordSourceInfo& info = source->info();
            ASSERT_EQ(info.pointCount, las.records.size());
            ASSERT_EQ(info.format.pointFormat, expectedOutputFormat(format));
            ASSERT_EQ(info.format.extraBytes, extraBytes);
            EXPECT_EQ(info.quantization.scale, las.scale);
            EXPECT_EQ(info.quantization.offset, las.offset);
            const std::vector<std::byte> records = readAllRecords(*source, 1000);
            ASSERT_EQ(records.size(), las.records.size() * info.format.recordLength());
            for (int i = 0; i < static_cast<int>(las.records.size()); ++i) {
                EXPECT_EQ(recordFields(records, info.format, static_cast<std::size_t>(i)),
                          expectedFields(format, i, extraBytes))
                    << "point " << i;
            }
            if (hasWavePacket(format)) {
                EXPECT_THAT(info.warnings,
                            Contains(AllOf(HasSubstr(path.string()), HasSubstr("wave packets"))));
            } else {
                EXPECT_THAT(info.warnings, IsEmpty());
            }
        }
    }
}

TEST(PointRecordSourceTest, ScanAngleRanksBecomeSixThousandthsOfADegree) {
    // The conversion on its own, for each rank of kRanks (the test above covers them too, mixed
    // with every other field).
    const test::TempDir dir;
    const auto source = open(
        dir.write("ranks.las", lasWithEveryField(1, 0, static_cast<int>(kRanks.size())).bytes()));
    const std::vector<std::byte> records = readAllRecords(*source, 100);
    for (std::size_t i = 0; i < kRanks.size(); ++i) {
        EXPECT_EQ(recordFields(records, source->info().format, i).scanAngle,
                  std::lround(kRanks[i] / 0.006))
            << "rank " << int{kRanks[i]};
    }
}

std::string floatDescriptor(std::string_view name) {
    std::string d(kDescriptorSize, '\0');
    d[2] = 9;  // float
    std::memcpy(d.data() + 4, name.data(), name.size());
    return d;
}

TEST(PointRecordSourceTest, ExtraBytesKeepTheFilesDescriptors) {
    TestLas las = lasWithEveryField(6, 8, 3);
    const std::string descriptors = floatDescriptor("Amplitude") + floatDescriptor("Deviation");
    las.vlrs.push_back({"LASF_Spec", 4, descriptors});
    const test::TempDir dir;
    const auto source = open(dir.write("extra.las", las.bytes()));
    const PointRecordFormat& format = source->info().format;
    EXPECT_EQ(format.extraBytes, 8u);
    ASSERT_EQ(format.extraBytesDescriptors.size(), descriptors.size());
    EXPECT_EQ(0, std::memcmp(format.extraBytesDescriptors.data(), descriptors.data(),
                             descriptors.size()));
    EXPECT_THAT(source->info().warnings, IsEmpty());
}

TEST(PointRecordSourceTest, ExtraBytesDescribedInAnExtendedVlrKeepThoseDescriptors) {
    TestLas las = lasWithEveryField(7, 4, 3);
    las.evlrs.push_back({"LASF_Spec", 4, floatDescriptor("Reflectance")});
    const test::TempDir dir;
    const auto source = open(dir.write("evlr.las", las.bytes()));
    const std::vector<std::byte>& descriptors = source->info().format.extraBytesDescriptors;
    ASSERT_EQ(descriptors.size(), kDescriptorSize);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(descriptors.data()) + 4), "Reflectance");
    EXPECT_EQ(readAllRecords(*source, 2).size(), 3 * source->info().format.recordLength());
}

TEST(PointRecordSourceTest, UndescribedExtraBytesAreDescribedAsUndocumented) {
    // R15 table 24: data type 0 is "undocumented extra bytes", the options byte their count.
    const test::TempDir dir;
    const auto source = open(dir.write("old.las", lasWithEveryField(3, 300, 2).bytes()));
    const std::vector<std::byte>& d = source->info().format.extraBytesDescriptors;
    ASSERT_EQ(d.size(), 2 * kDescriptorSize);  // 300 bytes: 255 + 45
    EXPECT_EQ(std::to_integer<int>(d[2]), 0);
    EXPECT_EQ(std::to_integer<int>(d[3]), 255);
    EXPECT_EQ(std::to_integer<int>(d[kDescriptorSize + 2]), 0);
    EXPECT_EQ(std::to_integer<int>(d[kDescriptorSize + 3]), 45);
    EXPECT_THAT(source->info().warnings, IsEmpty());

    // A descriptor VLR that does not add up to the extra bytes is not trusted, and said so.
    TestLas wrong = lasWithEveryField(6, 3, 2);
    wrong.vlrs.push_back({"LASF_Spec", 4, floatDescriptor("TooWide")});
    const auto mismatch = open(dir.write("wrong.las", wrong.bytes()));
    EXPECT_EQ(std::to_integer<int>(mismatch->info().format.extraBytesDescriptors[3]), 3);
    EXPECT_THAT(mismatch->info().warnings, Contains(HasSubstr("undocumented")));
}

TEST(PointRecordSourceTest, TheCoordinateSystemIsTheWktRecord) {
    const test::TempDir dir;
    TestLas las = lasWithEveryField(1, 0, 2);
    las.vlrs.push_back({"LASF_Projection", 34735, std::string(16, '\1')});
    las.vlrs.push_back({"LASF_Projection", 2112, std::string("PROJCS[\"test\"]\0\0", 16)});
    EXPECT_EQ(open(dir.write("wkt.las", las.bytes()))->info().wkt, "PROJCS[\"test\"]");

    TestLas extended = lasWithEveryField(6, 0, 2);
    extended.evlrs.push_back({"LASF_Projection", 2112, "GEOGCS[\"evlr\"]"});
    EXPECT_EQ(open(dir.write("evlr.las", extended.bytes()))->info().wkt, "GEOGCS[\"evlr\"]");

    // GeoTIFF keys alone: no WKT, and a warning that says so.
    TestLas geotiff = lasWithEveryField(1, 0, 2);
    geotiff.vlrs.push_back({"LASF_Projection", 34735, std::string(16, '\1')});
    const auto path = dir.write("geotiff.las", geotiff.bytes());
    const auto source = open(path);
    EXPECT_EQ(source->info().wkt, "");
    EXPECT_THAT(source->info().warnings,
                Contains(AllOf(HasSubstr(path.string()), HasSubstr("GeoTIFF"))));
}

/// Reads `source` in pieces of `piece` records, checking each read's count.
std::vector<std::byte> readInPieces(PointRecordSource& source, std::size_t piece) {
    std::vector<std::byte> records;
    const std::size_t length = source.info().format.recordLength();
    for (;;) {
        const std::size_t before = records.size();
        const std::size_t got = source.read(records, piece);
        EXPECT_LE(got, piece);
        EXPECT_EQ(records.size() - before, got * length);
        if (got == 0) {
            return records;
        }
    }
}

void expectPiecesAgree(PointRecordSource& source) {
    source.rewind();
    const std::vector<std::byte> whole = readAllRecords(source, source.info().pointCount);
    EXPECT_EQ(whole.size(), source.info().pointCount * source.info().format.recordLength());
    EXPECT_EQ(source.read(*std::make_unique<std::vector<std::byte>>(), 10), 0u) << "after the end";
    for (const std::size_t piece : {1, 7, 1000}) {
        source.rewind();
        EXPECT_EQ(readInPieces(source, piece), whole) << "pieces of " << piece;
    }
}

TEST(PointRecordSourceTest, PiecesAndRewindGiveTheSameRecordsAsOneRead) {
    const test::TempDir dir;
    // 70,000 records: more than one block of the LAS reader (65,536), and 7 does not divide it.
    const auto las = open(dir.write("big.las", lasWithEveryField(3, 2, 70000).bytes()));
    expectPiecesAgree(*las);
}

TEST(PointRecordSourceTest, ReadingNeverWritesTheInput) {
    const test::TempDir dir;
    const std::string bytes = lasWithEveryField(2, 0, 10).bytes();
    const auto path = dir.write("input.las", bytes);
    const auto written = std::filesystem::last_write_time(path);
    {
        const auto source = open(path);
        readAllRecords(*source, 3);
        source->rewind();
        readAllRecords(*source, 100);
    }
    EXPECT_EQ(test::fileBytes(path), bytes);
    EXPECT_EQ(std::filesystem::last_write_time(path), written);
}

TEST(PointRecordSourceTest, BadLasFilesAreOneSentenceNamingTheFile) {
    const test::TempDir dir;
    const auto expectError = [&](const std::string& name, const std::string& bytes,
                                 const std::string& what) {
        const auto path = dir.write(name, bytes);
        const std::string message = openError(path);
        EXPECT_THAT(message, AllOf(HasSubstr(path.string()), HasSubstr(what))) << name;
        EXPECT_EQ(test::fileBytes(path), bytes) << name;
    };
    // Truncated: the last record cut in half.
    std::string truncated = lasWithEveryField(3, 0, 10).bytes();
    truncated.resize(truncated.size() - 17);
    expectError("truncated.las", truncated, "declares 10 points, but the point data holds only 9");
    // A count larger than the records.
    TestLas counted = lasWithEveryField(1, 0, 10);
    counted.declaredCount = 11;
    expectError("count.las", counted.bytes(), "declares 11 points");
    // A record length shorter than the format.
    TestLas shortRecords = lasWithEveryField(3, 0, 0);
    shortRecords.recordLength = 28;
    expectError("short.las", shortRecords.bytes(), "record length 28 is shorter than the 34");
    expectError("none.las", lasWithEveryField(3, 0, 0).bytes(), "no points");
    expectError("empty.las", "", "empty");
    expectError("header.las", lasWithEveryField(3, 0, 3).bytes().substr(0, 100), "LAS header");
    // A point data offset of 300 MiB in a file that long (sparse: the test writes 300 bytes).
    std::string farPoints = lasWithEveryField(3, 0, 1).bytes();
    const std::uint32_t offset = 300u << 20;
    std::memcpy(farPoints.data() + 96, &offset, sizeof(offset));
    const auto farPath = dir.write("far.las", farPoints);
    std::filesystem::resize_file(farPath, offset + 34);
    EXPECT_THAT(openError(farPath), AllOf(HasSubstr("far.las"), HasSubstr("header corrupt")));
    TestLas unknown = lasWithEveryField(3, 0, 1);
    std::string badFormat = unknown.bytes();
    badFormat[104] = 11;
    expectError("format.las", badFormat, "point data format 11 is unknown");
}

/// A binary PLY file: float x y z, uchar red green blue, float nx ny nz, float intensity, with an
/// element before the vertices and faces after them.
std::string binaryPly(const std::vector<std::array<float, 10>>& vertices, bool bigEndian = false) {
    std::string out = "ply\nformat ";
    out += bigEndian ? "binary_big_endian" : "binary_little_endian";
    out += " 1.0\ncomment made by the test\nelement camera 1\nproperty double k\n";
    out += "element vertex " + std::to_string(vertices.size()) + "\n";
    out += "property float x\nproperty float y\nproperty float z\n";
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out += "property float nx\nproperty float ny\nproperty float nz\nproperty float intensity\n";
    out += "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    appendBytes(out, 2.5, bigEndian);
    for (const auto& v : vertices) {
        for (int k = 0; k < 10; ++k) {
            if (k >= 3 && k < 6) {
                appendBytes(out, static_cast<std::uint8_t>(v[k]), bigEndian);
            } else {
                appendBytes(out, v[k], bigEndian);
            }
        }
    }
    appendBytes<std::uint8_t>(out, 3);
    for (std::int32_t index : {0, 1, 2}) {
        appendBytes(out, index, bigEndian);
    }
    return out;
}

std::vector<std::array<float, 10>> plyVertices(int count) {
    std::vector<std::array<float, 10>> vertices;
    for (int i = 0; i < count; ++i) {
        const float angle = 0.1f * static_cast<float>(i);
        vertices.push_back({1.25f + 0.001f * static_cast<float>(i), -3.5f + std::sin(angle),
                            0.2f * std::cos(angle), static_cast<float>(i % 256),
                            static_cast<float>((7 * i) % 256), 255.0f, std::sin(angle), 0.0f,
                            std::cos(angle), 10.6f * static_cast<float>(i)});
    }
    return vertices;
}

glm::dvec3 fileCoordinates(const Las14Fields& f, const Quantization& q) {
    return glm::dvec3(f.xyz[0], f.xyz[1], f.xyz[2]) * q.scale + q.offset;
}

void expectPlyRecords(PointRecordSource& source, const std::vector<std::array<float, 10>>& v) {
    const PointRecordSourceInfo& info = source.info();
    ASSERT_EQ(info.pointCount, v.size());
    ASSERT_EQ(info.format.pointFormat, 7);
    ASSERT_EQ(info.format.extraBytes, 12u);
    // PDAL's names for normals, as float extra bytes (data type 9).
    const std::vector<std::byte>& d = info.format.extraBytesDescriptors;
    ASSERT_EQ(d.size(), 3 * kDescriptorSize);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(std::to_integer<int>(d[k * kDescriptorSize + 2]), 9);
        EXPECT_EQ(std::string(reinterpret_cast<const char*>(d.data()) + k * kDescriptorSize + 4),
                  std::string("Normal") + "XYZ"[k]);
    }
    const std::vector<std::byte> records = readAllRecords(source, 5);
    ASSERT_EQ(records.size(), v.size() * info.format.recordLength());
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Las14Fields f = recordFields(records, info.format, i);
        const glm::dvec3 p = fileCoordinates(f, info.quantization);
        for (int axis = 0; axis < 3; ++axis) {
            // Quantization rounds to the nearest step; doubles add nothing at these sizes.
            EXPECT_NEAR(p[axis], v[i][axis], 0.5 * info.quantization.scale[axis]) << i;
        }
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(f.rgb[c], static_cast<int>(v[i][3 + c]) * 257) << i;  // 8-bit * 257
        }
        float normal[3];
        std::memcpy(normal, f.extraBytes.data(), sizeof(normal));
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(normal[k], v[i][6 + k]) << i;  // the file's floats, bit for bit
        }
        EXPECT_EQ(f.intensity, std::lround(v[i][9])) << i;
        EXPECT_EQ(f.returnNumber, 1);
        EXPECT_EQ(f.numberOfReturns, 1);
        EXPECT_EQ(f.classification, 0);
    }
}

TEST(PointRecordSourceTest, BinaryPlyKeepsPositionsColourNormalsAndIntensity) {
    const test::TempDir dir;
    const auto vertices = plyVertices(50);
    for (const bool bigEndian : {false, true}) {
        SCOPED_TRACE(bigEndian ? "big endian" : "little endian");
        const auto source = open(dir.write("normals.ply", binaryPly(vertices, bigEndian)));
        expectPlyRecords(*source, vertices);
        // The stored bounds hold every point, and are the extreme points' stored coordinates.
        const PointRecordSourceInfo& info = source->info();
        EXPECT_NEAR(info.min.x, 1.25, 0.5 * info.quantization.scale.x);
        EXPECT_NEAR(info.max.x, vertices.back()[0], 0.5 * info.quantization.scale.x);
        expectPiecesAgree(*source);
    }
}

TEST(PointRecordSourceTest, AsciiPlyIsLoadedWholeWithTheSameRecords) {
    const auto vertices = plyVertices(20);
    std::string ascii =
        "ply\nformat ascii 1.0\nelement vertex 20\nproperty float x\nproperty float y\n"
        "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
        "property float nx\nproperty float ny\nproperty float nz\nproperty float intensity\n"
        "end_header\n";
    for (const auto& v : vertices) {
        for (int k = 0; k < 10; ++k) {
            ascii += fmt::format("{} ", v[k]);  // shortest text that reads back as this float
        }
        ascii += "\n";
    }
    const test::TempDir dir;
    const auto source = open(dir.write("ascii.ply", ascii));
    // Loaded whole, positions pass through the cloud's floats relative to its origin: at these
    // coordinates (|x| < 5) a float step is below 5e-7, the tolerance below adds that.
    const PointRecordSourceInfo& info = source->info();
    const std::vector<std::byte> records = readAllRecords(*source, 1000);
    ASSERT_EQ(info.pointCount, vertices.size());
    ASSERT_EQ(info.format.extraBytes, 12u);
    for (std::size_t i = 0; i < vertices.size(); ++i) {
        const Las14Fields f = recordFields(records, info.format, i);
        const glm::dvec3 p = fileCoordinates(f, info.quantization);
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(p[axis], vertices[i][axis], 0.5 * info.quantization.scale[axis] + 5e-7);
        }
        EXPECT_EQ(f.rgb[1], static_cast<int>(vertices[i][4]) * 257);
    }
}

TEST(PointRecordSourceTest, IntensitiesLasCannotHoldAreNamed) {
    // A scanner's 0..1 confidence and a Leica PTS file's -2048..2047 were written rounded and
    // clamped without a word (the bunny's 7,277 intensities became 0 and 1): each kind of
    // source says so, and whole numbers within 0..65535 pass without a word.
    const test::TempDir dir;
    auto intensityWarnings = [](const PointRecordSource& source) {
        int count = 0;
        for (const std::string& warning : source.info().warnings) {
            count += warning.find("intensities are not all whole numbers") != std::string::npos;
        }
        return count;
    };
    std::vector<std::array<float, 10>> whole = plyVertices(20);
    for (std::size_t i = 0; i < whole.size(); ++i) {
        whole[i][9] = static_cast<float>(1000 * i);
    }
    EXPECT_EQ(intensityWarnings(*open(dir.write("whole.ply", binaryPly(whole)))), 0);
    EXPECT_EQ(intensityWarnings(*open(dir.write("fraction.ply", binaryPly(plyVertices(20))))), 1);
    EXPECT_EQ(intensityWarnings(*open(dir.write("whole.xyz", "x y z i\n0 0 0 7\n1 0 0 65535\n"))),
              0);
    EXPECT_EQ(intensityWarnings(*open(dir.write("pts.xyz", "x y z i\n0 0 0 -2048\n1 0 0 2047\n"))),
              1);
    // Loaded whole (ascii PLY).
    EXPECT_EQ(intensityWarnings(
                  *open(dir.write("ascii.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                  "property float y\nproperty float z\nproperty float intensity\n"
                                  "end_header\n0 0 0 0.25\n1 0 0 0.5\n"))),
              1);
}

TEST(PointRecordSourceTest, ColourCutTo8BitsByALoadedWholeInputIsNamed) {
    // An ascii PLY (like a PCD or an E57 file) is loaded whole, as 8-bit colour: its 16-bit
    // colour reached COPC cut to 8 bits without a word, where convert names the cut.
    const test::TempDir dir;
    auto cutWarnings = [](const PointRecordSource& source) {
        int count = 0;
        for (const std::string& warning : source.info().warnings) {
            count += warning.find("colour of more than 8 bits a channel is cut to 8 bits") !=
                     std::string::npos;
        }
        return count;
    };
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nproperty ushort red\nproperty ushort green\nproperty ushort blue\n"
        "end_header\n";
    EXPECT_EQ(cutWarnings(*open(dir.write("deep.ply", header + "0 0 0 1000 2000 65535\n"
                                                               "1 0 0 300 40000 7\n"))),
              1);
    // 8-bit values times 257, as LAS writers store 8-bit colour: nothing is cut.
    EXPECT_EQ(cutWarnings(*open(dir.write("bytes.ply", header + "0 0 0 257 514 65535\n"
                                                                "1 0 0 0 2570 771\n"))),
              0);
}

/// A binary PLY of float x y z and colour channels of `type`, one vertex per colour.
template <class Channel>
std::string binaryColorPly(const char* type, const std::vector<std::array<Channel, 3>>& colors) {
    std::string out = fmt::format(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n"
        "property float y\nproperty float z\nproperty {} red\nproperty {} green\n"
        "property {} blue\nend_header\n",
        colors.size(), type, type, type);
    for (std::size_t i = 0; i < colors.size(); ++i) {
        for (const float coordinate : {static_cast<float>(i), 0.0f, 0.0f}) {
            appendBytes(out, coordinate);
        }
        for (const Channel c : colors[i]) {
            appendBytes(out, c);
        }
    }
    return out;
}

/// The LAS colour words of every record of `source`.
std::vector<std::array<std::uint16_t, 3>> recordColors(PointRecordSource& source) {
    const std::vector<std::byte> records = readAllRecords(source, 2);
    std::vector<std::array<std::uint16_t, 3>> colors;
    for (std::size_t i = 0; i < source.info().pointCount; ++i) {
        colors.push_back(recordFields(records, source.info().format, i).rgb);
    }
    return colors;
}

TEST(PointRecordSourceTest, PlyColourScaleIsJudgedFromEveryVertexAsTheReaderDoes) {
    using Words = std::vector<std::array<std::uint16_t, 3>>;
    using Floats = std::vector<std::array<float, 3>>;
    const test::TempDir dir;
    // 8-bit values in ushort (PDAL's LAS colour) were divided by 257: near black.
    EXPECT_EQ(recordColors(*open(dir.write(
                  "bytes.ply",
                  binaryColorPly<std::uint16_t>("ushort", Words{{248, 149, 136}, {0, 255, 100}})))),
              (Words{{248 * 257, 149 * 257, 136 * 257}, {0, 255 * 257, 100 * 257}}));
    // A value above 255 in the last vertex makes the file's colour 16-bit, from the first on.
    EXPECT_EQ(recordColors(*open(
                  dir.write("words.ply", binaryColorPly<std::uint16_t>(
                                             "ushort", Words{{248, 149, 136}, {0, 255, 1000}})))),
              (Words{{248, 149, 136}, {0, 255, 1000}}));
    // Float colour 0..255 was taken as 0..1 and clamped.
    EXPECT_EQ(recordColors(*open(dir.write(
                  "floats.ply",
                  binaryColorPly<float>("float", Floats{{255.0f, 128.0f, 0.0f}, {1, 1, 1}})))),
              (Words{{255 * 257, 128 * 257, 0}, {257, 257, 257}}));
    EXPECT_EQ(
        recordColors(*open(dir.write(
            "units.ply", binaryColorPly<float>("float", Floats{{1.0f, 0.5f, 0.0f}, {0, 0, 1}})))),
        (Words{{65535, 32768, 0}, {0, 0, 65535}}));
}

TEST(PointRecordSourceTest, BadPlyFilesAreOneSentenceNamingTheFileAndField) {
    const test::TempDir dir;
    auto vertices = plyVertices(5);
    vertices[3][1] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THAT(openError(dir.write("nan.ply", binaryPly(vertices))),
                AllOf(HasSubstr("nan.ply"), HasSubstr("vertex 4 of 5"), HasSubstr("y coordinate")));
    vertices[3][1] = std::numeric_limits<float>::infinity();
    EXPECT_THAT(openError(dir.write("inf.ply", binaryPly(vertices))),
                AllOf(HasSubstr("inf.ply"), HasSubstr("vertex 4 of 5"), HasSubstr("inf")));
    std::string truncated = binaryPly(plyVertices(5));
    truncated.resize(truncated.size() - 13 - 20);  // the face and 20 of the last vertex's 31
    EXPECT_THAT(openError(dir.write("cut.ply", truncated)),
                AllOf(HasSubstr("cut.ply"), HasSubstr("ends inside vertex 5 of 5")));
    EXPECT_THAT(openError(dir.write("none.ply", binaryPly({}))),
                AllOf(HasSubstr("none.ply"), HasSubstr("no points")));
    EXPECT_THAT(openError(dir.write("noz.ply",
                                    "ply\nformat binary_little_endian 1.0\n"
                                    "element vertex 1\nproperty float x\n"
                                    "property float y\nend_header\n12345678")),
                AllOf(HasSubstr("noz.ply"), HasSubstr("no 'z' property")));
}

/// A text list of `count` points "x y z r g b nx ny nz", with a header line.
std::string pointText(int count) {
    std::string text = "x y z r g b nx ny nz\n";
    for (int i = 0; i < count; ++i) {
        text += fmt::format("{:.3f} {:.3f} {:.3f} {} {} {} 0 0.6 0.8\n", 100.0 + 0.001 * i,
                            -5.0 - 0.002 * i, 0.5 * (i % 100), i % 256, (3 * i) % 256, 7);
    }
    return text;
}

TEST(PointRecordSourceTest, TextListsStreamThroughPiecesOfLines) {
    // 40,000 lines of about 40 bytes: 1.6 MB, more than one piece of the reader (1 MiB), so the
    // pieces' seams lie inside the file.
    const int count = 40000;
    const test::TempDir dir;
    const auto source = open(dir.write("points.xyz", pointText(count)));
    const PointRecordSourceInfo& info = source->info();
    ASSERT_EQ(info.pointCount, static_cast<std::uint64_t>(count));
    EXPECT_EQ(info.format.pointFormat, 7);
    EXPECT_EQ(info.format.extraBytes, 12u);
    // The bounds' power-of-ten scale for a 100 m wide cloud: the finest that fits int32.
    EXPECT_EQ(info.quantization.scale, glm::dvec3(1e-7));
    const std::vector<std::byte> records = readAllRecords(*source, 4096);
    ASSERT_EQ(records.size(), count * info.format.recordLength());
    for (const int i : {0, 1, 26000, count - 1}) {
        const Las14Fields f = recordFields(records, info.format, static_cast<std::size_t>(i));
        const glm::dvec3 p = fileCoordinates(f, info.quantization);
        // Three decimals on a grid of 1e-7: exact up to doubles' rounding at 100 (1.5e-14).
        EXPECT_NEAR(p.x, 100.0 + 0.001 * i, 1e-9);
        EXPECT_NEAR(p.y, -5.0 - 0.002 * i, 1e-9);
        EXPECT_NEAR(p.z, 0.5 * (i % 100), 1e-9);
        EXPECT_EQ(f.rgb[0], (i % 256) * 257);
        EXPECT_EQ(f.rgb[2], 7 * 257);
        float normal[3];
        std::memcpy(normal, f.extraBytes.data(), sizeof(normal));
        EXPECT_EQ(normal[1], 0.6f);
    }
    expectPiecesAgree(*source);
}

TEST(PointRecordSourceTest, TextColourEncodingIsJudgedFromEveryLine) {
    // 150 dark points, then 16-bit colour: the first 100 lines decided, and later values were
    // clamped to 255 (white).
    std::string text = "x y z r g b\n";
    for (int i = 0; i < 1000; ++i) {
        const int value = i < 150 ? i : 20000 + 45 * i;
        text += fmt::format("{} 0 0 {} 0 {}\n", i, value, value);
    }
    const test::TempDir dir;
    const auto source = open(dir.write("dark.xyz", text));
    const std::vector<std::array<std::uint16_t, 3>> colors = recordColors(*source);
    ASSERT_EQ(colors.size(), 1000u);
    EXPECT_EQ(colors[149], (std::array<std::uint16_t, 3>{149, 0, 149}));
    EXPECT_EQ(colors[999], (std::array<std::uint16_t, 3>{64955, 0, 64955}));
}

TEST(PointRecordSourceTest, BadTextListsAreOneSentenceNamingTheFileAndLine) {
    const test::TempDir dir;
    EXPECT_THAT(openError(dir.write("nan.xyz", "1 2 3\n4 nan 6\n")),
                AllOf(HasSubstr("nan.xyz"), HasSubstr("line 2"), HasSubstr("y coordinate")));
    EXPECT_THAT(openError(dir.write("inf.xyz", "1 2 3\n4 5 6\n7 8 -inf\n")),
                AllOf(HasSubstr("inf.xyz"), HasSubstr("line 3"), HasSubstr("z coordinate")));
    EXPECT_THAT(openError(dir.write("words.xyz", "1 2 3\n4 five 6\n")),
                AllOf(HasSubstr("words.xyz"), HasSubstr("line 2"), HasSubstr("'five'")));
    EXPECT_THAT(openError(dir.write("header.xyz", "x y z\n")),
                AllOf(HasSubstr("header.xyz"), HasSubstr("no points")));
    EXPECT_THAT(openError(dir.write("counts.pts", "0\n")), HasSubstr("counts.pts"));
    // A point line, then 100 MiB without a line end (a sparse file of zeros).
    const auto endless = dir.write("endless.xyz", "1 2 3\n" + std::string(5000, '4'));
    std::filesystem::resize_file(endless, 100u << 20);
    EXPECT_THAT(openError(endless), AllOf(HasSubstr("endless.xyz"), HasSubstr("longer than 64")));
    EXPECT_THAT(openError(dir.write("pts.pts", "3\n1 2 3\n4 5 6\n")),
                AllOf(HasSubstr("pts.pts"), HasSubstr("says 3 points, but 2 follow")));
}

TEST(PointRecordSourceTest, ScansLoadedWholeBecomeRecordsToo) {
    const auto synthetic = open("synthetic:sphere?points=500");
    EXPECT_EQ(synthetic->info().name, "synthetic:sphere?points=500");
    EXPECT_GT(synthetic->info().pointCount, 0u);
    EXPECT_EQ(readAllRecords(*synthetic, 64).size(),
              synthetic->info().pointCount * synthetic->info().format.recordLength());
    EXPECT_THAT(test::errorMessage([] { open("synthetic:teapot"); }), HasSubstr("teapot"));
    EXPECT_THAT(test::errorMessage([] { open("/nonexistent/scan.las"); }),
                HasSubstr("/nonexistent/scan.las"));
}

TEST(PointRecordSourceTest, ACloudsClassificationCodesAreKept) {
    PointCloud cloud;
    cloud.positions = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
    cloud.classifications = {2, 6, 0};
    const auto source = cloudRecordSource(std::move(cloud), "classified");
    const std::vector<std::byte> records = readAllRecords(*source, 2);
    const std::size_t length = source->info().format.recordLength();
    ASSERT_EQ(records.size(), 3 * length);
    const std::array<int, 3> expected{2, 6, 0};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(std::to_integer<int>(records[i * length + las14::kClassification]), expected[i]);
    }
}

std::vector<std::byte> bytesOf(std::string_view text) {
    const auto* data = reinterpret_cast<const std::byte*>(text.data());
    return {data, data + text.size()};
}

/// The LAZ file of a LAS 1.4 file (its header, VLRs, records and EVLRs) in chunks of these
/// sizes, as subscan's LAZ writer encodes it.
std::string lazOf(const TestLas& las, std::vector<std::uint64_t> chunkPointCounts) {
    const std::string lasBytes = las.bytes();
    std::string records;
    for (const std::string& record : las.records) {
        records += record;
    }
    LazFileContents contents;
    contents.header = bytesOf(std::string_view(lasBytes).substr(0, 375));
    for (const Vlr& vlr : las.vlrs) {
        contents.vlrs.push_back({vlr.user, vlr.recordId, "", bytesOf(vlr.payload)});
    }
    for (const Vlr& evlr : las.evlrs) {
        contents.extendedVlrs.push_back({evlr.user, evlr.recordId, "", bytesOf(evlr.payload)});
    }
    contents.records = std::as_bytes(std::span(records));
    contents.chunkPointCounts = std::move(chunkPointCounts);
    const std::vector<std::byte> encoded = encodeLazFile(contents);
    return {reinterpret_cast<const char*>(encoded.data()), encoded.size()};
}

TEST(PointRecordSourceTest, LazOfUnevenChunksGivesTheRecordsOfTheSameLasFile) {
    // Format 8 with 3 extra bytes described as three uchar fields, and the WKT as an extended
    // VLR after the chunk table: the LAZ file is the LAS file's header and records encoded by
    // subscan's LAZ writer, in chunks of 1, 7, 992 and 1000 points.
    std::string descriptors;
    for (const char* name : {"a", "b", "c"}) {
        std::string d(kDescriptorSize, '\0');
        d[2] = 1;  // unsigned char
        std::memcpy(d.data() + 4, name, 1);
        descriptors += d;
    }
    TestLas las = lasWithEveryField(8, 3, 2000);
    las.vlrs.push_back({"LASF_Spec", 4, descriptors});
    las.evlrs.push_back({"LASF_Projection", 2112, "LOCAL_CS[\"site\"]"});
    const test::TempDir dir;
    const auto lazPath = dir.write("uneven.laz", lazOf(las, {1, 7, 992, 1000}));
    const auto lasSource = open(dir.write("uneven.las", las.bytes()));
    const std::vector<std::byte> expected = readAllRecords(*lasSource, 5000);
    for (const unsigned threads : {1u, 3u}) {
        SCOPED_TRACE(::testing::Message() << threads << " threads");
        const auto laz = open(lazPath, threads);
        EXPECT_EQ(laz->info().format, lasSource->info().format);
        EXPECT_EQ(laz->info().format.extraBytesDescriptors.size(), descriptors.size());
        EXPECT_EQ(laz->info().wkt, "LOCAL_CS[\"site\"]");
        EXPECT_EQ(laz->info().wkt, lasSource->info().wkt);
        EXPECT_TRUE(readAllRecords(*laz, 5000) == expected);
        expectPiecesAgree(*laz);
    }
}

TEST(PointRecordSourceTest, BadLazFilesAreOneSentenceNamingTheFile) {
    const std::string laz = lazOf(lasWithEveryField(7, 0, 100), {60, 40});
    const test::TempDir dir;
    const auto expectError = [&](const std::string& name, const std::string& bytes,
                                 const std::string& what) {
        const auto path = dir.write(name, bytes);
        EXPECT_THAT(openError(path), AllOf(HasSubstr(path.string()), HasSubstr(what))) << name;
    };
    // The header's 64-bit count (R15 table 3, byte 247) one more than the chunks hold.
    std::string counted = laz;
    const std::uint64_t more = 101;
    std::memcpy(counted.data() + 247, &more, sizeof(more));
    expectError("count.laz", counted, "chunks hold 100 points, but the LAS header declares 101");
    // The laszip VLR (the only VLR, right after the 375-byte header) names compressor 1, the
    // unchunked one of LASzip 1.x.
    std::string compressor = laz;
    ASSERT_EQ(compressor.substr(375 + 2, 14), "laszip encoded");
    compressor[375 + 54] = 1;
    expectError("compressor.laz", compressor, "compressor 1");
    expectError("cut.laz", laz.substr(0, laz.size() - 20), "chunk table");
}

// ---------------------------------------------------------------------------------------------
// Merging

/// A format 6 (or 7) file of three points whose stored X are 0, 1 and 2.
std::string threePointLas(int format, glm::dvec3 scale, glm::dvec3 offset,
                          std::vector<Vlr> vlrs = {}, std::size_t extraBytes = 0) {
    TestLas las = lasWithEveryField(format, extraBytes, 3);
    las.scale = scale;
    las.offset = offset;
    las.vlrs = std::move(vlrs);
    return las.bytes();
}

std::vector<std::unique_ptr<PointRecordSource>> openAll(
    const std::vector<std::filesystem::path>& paths) {
    std::vector<std::unique_ptr<PointRecordSource>> sources;
    for (const auto& path : paths) {
        sources.push_back(open(path));
    }
    return sources;
}

std::string mergeError(const std::vector<std::filesystem::path>& paths) {
    return test::errorMessage([&] { mergePointRecordSources(openAll(paths)); });
}

TEST(PointRecordSourceTest, MergedInputsShareOneGridKeepingEveryCoordinate) {
    const test::TempDir dir;
    // Offsets 0.25 and 12.75 apart: 1250 steps of 0.01 in x, -30 in z; the first is the grid.
    const auto a = dir.write("a.las", threePointLas(6, glm::dvec3(0.01), {1000.0, 0.0, 5.0}));
    const auto b = dir.write("b.las", threePointLas(7, glm::dvec3(0.01), {1012.5, 0.0, 4.7}));
    const auto merged = mergePointRecordSources(openAll({a, b}));
    const PointRecordSourceInfo& info = merged->info();
    EXPECT_EQ(info.pointCount, 6u);
    EXPECT_EQ(info.format.pointFormat, 7);  // the widest
    EXPECT_EQ(info.quantization.offset, glm::dvec3(1000.0, 0.0, 5.0));
    EXPECT_THAT(info.warnings, Contains(AllOf(HasSubstr(a.string()), HasSubstr("RGB 0"))));
    const std::vector<std::byte> records = readAllRecords(*merged, 4);
    ASSERT_EQ(records.size(), 6 * info.format.recordLength());
    for (std::size_t i = 0; i < 6; ++i) {
        const Las14Fields f = recordFields(records, info.format, i);
        const int format = i < 3 ? 6 : 7;
        Las14Fields expected = expectedFields(format, static_cast<int>(i % 3), 0);
        if (i >= 3) {
            expected.xyz[0] += 1250;  // (1012.5 - 1000) / 0.01
            expected.xyz[2] -= 30;    // (4.7 - 5) / 0.01, offsets of doubles rounded to steps
        }
        EXPECT_EQ(f, expected) << "record " << i;
    }
    merged->rewind();
    EXPECT_EQ(readAllRecords(*merged, 1), records);
}

TEST(PointRecordSourceTest, InputsThatCannotShareAGridAreOneSentenceNamingBoth) {
    const test::TempDir dir;
    const auto a = dir.write("a.las", threePointLas(6, glm::dvec3(0.01), glm::dvec3(0.0)));
    const auto fine = dir.write("fine.las", threePointLas(6, glm::dvec3(0.001), glm::dvec3(0.0)));
    EXPECT_THAT(mergeError({a, fine}),
                AllOf(HasSubstr("fine.las: its scale 0.001"), HasSubstr("of " + a.string()),
                      HasSubstr("index them separately")));
    const auto half = dir.write("half.las", threePointLas(6, glm::dvec3(0.01), {0.005, 0, 0}));
    EXPECT_THAT(mergeError({a, half}),
                AllOf(HasSubstr("half.las: its x offset 0.005"), HasSubstr(a.string())));
    std::string descriptor(kDescriptorSize, '\0');
    descriptor[2] = 9;
    std::memcpy(descriptor.data() + 4, "NormalX", 7);
    const auto extra = dir.write("extra.las", threePointLas(6, glm::dvec3(0.01), glm::dvec3(0.0),
                                                            {{"LASF_Spec", 4, descriptor}}, 4));
    EXPECT_THAT(mergeError({a, extra}),
                AllOf(HasSubstr("extra.las: its extra bytes (NormalX: 4 bytes)"),
                      HasSubstr("(none: 0 bytes) of " + a.string())));
    const auto wktA =
        dir.write("wa.las", threePointLas(6, glm::dvec3(0.01), glm::dvec3(0.0),
                                          {{"LASF_Projection", 2112, "LOCAL_CS[\"a\"]"}}));
    const auto wktB =
        dir.write("wb.las", threePointLas(6, glm::dvec3(0.01), glm::dvec3(0.0),
                                          {{"LASF_Projection", 2112, "LOCAL_CS[\"b\"]"}}));
    EXPECT_THAT(mergeError({wktA, a, wktB}),
                AllOf(HasSubstr("wb.las: its coordinate system"), HasSubstr(wktA.string())));
    // A WKT on one side only is the merged one.
    EXPECT_EQ(mergePointRecordSources(openAll({a, wktA}))->info().wkt, "LOCAL_CS[\"a\"]");
    // Far apart: no one grid of 32-bit integers at 0.01 holds 0 and 1e8.
    const auto far = dir.write("far.las", threePointLas(6, glm::dvec3(0.01), {1e8, 0, 0}));
    EXPECT_THAT(mergeError({a, far}), HasSubstr("too far apart"));
}

TEST(PointRecordSourceTest, InputsThatAreNotLasShareTheFinestGridThatHoldsThemAll) {
    // Alone, the 1 m scan gets steps of 1e-9 and the 9 km one 1e-5 in x: a merge refused them
    // (found by the outside hunt). Together they get the grid of their combined bounds.
    const test::TempDir dir;
    const std::vector<glm::dvec3> smallPoints{{0.125, 0.25, 0.5}, {1.0, 0.75, 0.375}};
    const std::vector<glm::dvec3> largePoints{{1000.5, 2000.25, 10.0}, {9000.75, -3000.5, 20.0}};
    const auto small = dir.write("small.xyz", "0.125 0.250 0.500\n1.000 0.750 0.375\n");
    const auto large = dir.write("large.xyz", "1000.5 2000.25 10\n9000.75 -3000.5 20\n");
    EXPECT_NE(open(small)->info().quantization, open(large)->info().quantization);
    const auto merged = mergePointRecordSources(openAll({small, large}));
    const PointRecordSourceInfo& info = merged->info();
    Bounds combined;
    for (const auto* points : {&smallPoints, &largePoints}) {
        for (const glm::dvec3& p : *points) {
            combined.add(p);
        }
    }
    const LasScaling expected = chooseLasScaling(combined);
    EXPECT_EQ(info.quantization, (Quantization{expected.scale, expected.offset}));
    EXPECT_EQ(info.quantization.scale, glm::dvec3(1e-5, 1e-5, 1e-8));
    EXPECT_THAT(info.warnings, IsEmpty());  // 3 decimals at most: every one kept
    const std::vector<std::byte> records = readAllRecords(*merged, 3);
    ASSERT_EQ(records.size(), 4 * info.format.recordLength());
    for (std::size_t i = 0; i < 4; ++i) {
        const Las14Fields f = recordFields(records, info.format, i);
        const glm::dvec3 stored(f.xyz[0], f.xyz[1], f.xyz[2]);
        const glm::dvec3 position = stored * info.quantization.scale + info.quantization.offset;
        const glm::dvec3 original = i < 2 ? smallPoints[i] : largePoints[i - 2];
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_NEAR(position[axis], original[axis], 1e-9) << "point " << i;
        }
    }

    // 7 decimals are more than the shared grid's 5 keep: said, naming the input.
    const auto fine = dir.write("fine.xyz", "0.1234567 0.5 0.25\n1 1 1\n");
    EXPECT_THAT(mergePointRecordSources(openAll({fine, large}))->info().warnings,
                Contains(AllOf(HasSubstr(fine.string() + ": its coordinates are written to "
                                                         "steps of 1e-07"),
                               HasSubstr("has steps of 1e-05: they are rounded to it"))));
}

TEST(PointRecordSourceTest, AMergeOfManyFilesHoldsOneOpenAtATime) {
    // 300 inputs under a limit of 64 open files: an input holds its file only while it is read.
    const test::TempDir dir;
    std::vector<std::filesystem::path> paths;
    for (int i = 0; i < 300; ++i) {
        paths.push_back(dir.write("tile" + std::to_string(i) + ".las",
                                  threePointLas(7, glm::dvec3(0.01), {10.0 * i, 0.0, 0.0})));
    }
    rlimit saved{};
    ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &saved), 0);
    rlimit limited = saved;
    limited.rlim_cur = std::min<rlim_t>(saved.rlim_cur, 64);
    ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &limited), 0);
    std::size_t records = 0;
    try {
        const auto merged = mergePointRecordSources(openAll(paths));
        for (int pass = 0; pass < 2; ++pass) {
            merged->rewind();
            records = readAllRecords(*merged, 5).size() / merged->info().format.recordLength();
        }
    } catch (const Error& error) {
        ADD_FAILURE() << error.what();
    }
    setrlimit(RLIMIT_NOFILE, &saved);
    EXPECT_EQ(records, 900u);
}

TEST(PointRecordSourceTest, NearInfraredMissingFromAnInputIsZero) {
    const test::TempDir dir;
    const auto rgb = dir.write("rgb.las", threePointLas(7, glm::dvec3(0.01), glm::dvec3(0.0)));
    const auto nir = dir.write("nir.las", threePointLas(8, glm::dvec3(0.01), glm::dvec3(0.0)));
    const auto merged = mergePointRecordSources(openAll({rgb, nir}));
    EXPECT_EQ(merged->info().format.pointFormat, 8);
    EXPECT_THAT(merged->info().warnings, Contains(HasSubstr("NIR 0")));
    const std::vector<std::byte> records = readAllRecords(*merged, 100);
    const Las14Fields first = recordFields(records, merged->info().format, 1);
    EXPECT_EQ(first.rgb, expectedFields(7, 1, 0).rgb);
    EXPECT_EQ(first.nir, 0);
    EXPECT_EQ(recordFields(records, merged->info().format, 4).nir, expectedFields(8, 1, 0).nir);
}

}  // namespace
}  // namespace subscan

namespace subscan {
namespace {

/// A three-point file of `format` with this header's file source ID and global encoding.
std::string lasWithHeaderIds(int format, std::uint16_t fileSourceId, std::uint16_t encoding) {
    TestLas las = lasWithEveryField(format, 0, 3);
    las.fileSourceId = fileSourceId;
    las.globalEncoding = encoding;
    return las.bytes();
}

std::uint16_t headerWord(const std::vector<std::byte>& header, std::size_t offset) {
    std::uint16_t value = 0;
    std::memcpy(&value, header.data() + offset, sizeof value);
    return value;
}

TEST(PointRecordSourceTest, TheKindOfGpsTimeAndTheFileSourceIdReachTheWrittenHeader) {
    const test::TempDir dir;
    const auto standard = open(dir.write("standard.las", lasWithHeaderIds(1, 1234, 1)));
    EXPECT_EQ(standard->info().standardGpsTime, std::optional<bool>(true));
    EXPECT_EQ(standard->info().fileSourceId, 1234);
    const std::vector<std::byte> header = las14Header(standard->info(), {}, "test");
    EXPECT_EQ(headerWord(header, 4), 1234);    // file source ID
    EXPECT_EQ(headerWord(header, 6), 1 | 16);  // standard GPS time, and WKT as formats 6-8 need
    const auto week = open(dir.write("week.las", lasWithHeaderIds(3, 7, 0)));
    EXPECT_EQ(week->info().standardGpsTime, std::optional<bool>(false));
    EXPECT_EQ(headerWord(las14Header(week->info(), {}, "test"), 6), 16);
    // Format 2 has no GPS times: whatever its bit 0 says means nothing.
    const auto none = open(dir.write("none.las", lasWithHeaderIds(2, 7, 1)));
    EXPECT_EQ(none->info().standardGpsTime, std::nullopt);
}

TEST(PointRecordSourceTest, AMergeKeepsTheKindOfGpsTimeAndACommonFileSourceId) {
    const test::TempDir dir;
    const auto a = dir.write("a.las", lasWithHeaderIds(1, 5, 1));
    const auto b = dir.write("b.las", lasWithHeaderIds(3, 5, 1));
    const auto c = dir.write("c.las", lasWithHeaderIds(6, 6, 1));
    const auto noTimes = dir.write("d.las", lasWithHeaderIds(2, 5, 0));
    const auto same = mergePointRecordSources(openAll({a, b, noTimes}));
    EXPECT_EQ(same->info().standardGpsTime, std::optional<bool>(true));
    EXPECT_EQ(same->info().fileSourceId, 5);
    EXPECT_EQ(mergePointRecordSources(openAll({a, c}))->info().fileSourceId, 0);
    const auto week = dir.write("week.las", lasWithHeaderIds(1, 5, 0));
    EXPECT_THAT(mergeError({a, week}),
                AllOf(HasSubstr(week.string()), HasSubstr(a.string()),
                      HasSubstr("GPS week seconds"), HasSubstr("global encoding bit 0")));
}

}  // namespace
}  // namespace subscan
