// The E57 reader on files built here by a small writer of its own: pages with their CRC-32C,
// the XML section, compressed vectors with bit-packed fields in data packets; then the bad
// inputs, each refused with one sentence.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/E57Reader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::appendBytes;
using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

constexpr std::size_t kPage = 1024;
constexpr std::size_t kPageData = 1020;

/// CRC-32C bit by bit, written independently of the reader's table-driven one.
std::uint32_t bitwiseCrc32c(const char* data, std::size_t size) {
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < size; ++i) {
        crc ^= static_cast<unsigned char>(data[i]);
        for (int bit = 0; bit < 8; ++bit) {
            crc = (crc & 1u) != 0 ? (crc >> 1) ^ 0x82F63B78u : crc >> 1;
        }
    }
    return ~crc;
}

/// One prototype field: how the XML declares it and the bit patterns its bytestream holds.
struct TestField {
    std::string name;
    std::string xml;  // the attributes after the name, e.g. type="Integer" minimum="0" ...
    unsigned bits = 0;
    std::vector<std::uint64_t> raw;  // one stored value per record
};

/// Bits for values min..max, counted here rather than with the reader's formula.
unsigned bitsFor(std::int64_t minimum, std::int64_t maximum) {
    const std::uint64_t range =
        static_cast<std::uint64_t>(maximum) - static_cast<std::uint64_t>(minimum);
    unsigned bits = 0;
    while (bits < 64 && (range >> bits) != 0) {
        ++bits;
    }
    return bits;
}

TestField doubleField(const std::string& name, const std::vector<double>& values) {
    TestField field{name, R"(type="Float")", 64, {}};
    for (double v : values) {
        std::uint64_t bits = 0;
        std::memcpy(&bits, &v, sizeof(v));
        field.raw.push_back(bits);
    }
    return field;
}

TestField singleField(const std::string& name, const std::vector<float>& values) {
    TestField field{name, R"(type="Float" precision="single")", 32, {}};
    for (float v : values) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &v, sizeof(v));
        field.raw.push_back(bits);
    }
    return field;
}

TestField integerField(const std::string& name, std::int64_t minimum, std::int64_t maximum,
                       const std::vector<std::int64_t>& values) {
    TestField field{name,
                    fmt::format(R"(type="Integer" minimum="{}" maximum="{}")", minimum, maximum),
                    bitsFor(minimum, maximum),
                    {}};
    for (std::int64_t v : values) {
        field.raw.push_back(static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(minimum));
    }
    return field;
}

/// A ScaledInteger field holding the stored integers `values` (file value = v * scale + offset).
TestField scaledField(const std::string& name, std::int64_t minimum, std::int64_t maximum,
                      double scale, double offset, const std::vector<std::int64_t>& values) {
    TestField field = integerField(name, minimum, maximum, values);
    field.xml = fmt::format(
        R"(type="ScaledInteger" minimum="{}" maximum="{}" scale="{:.17g}" offset="{:.17g}")",
        minimum, maximum, scale, offset);
    return field;
}

struct TestScan {
    std::vector<TestField> fields;
    std::optional<std::string> recordCount;  // default: the first field's value count
    std::optional<std::string> fileOffset;   // default: where the section is written
    std::string extraXml;                    // pose, colorLimits, ...
    std::size_t chunkBytes = 1000;           // each stream's bytes per data packet
    std::optional<std::uint8_t> packetType;  // override for the data packets' type byte
};

/// Values packed least significant bit first, continuing across byte boundaries.
std::string bitPack(const TestField& field) {
    std::string bytes;
    unsigned used = 8;
    for (const std::uint64_t value : field.raw) {
        for (unsigned bit = 0; bit < field.bits; ++bit) {
            if (used == 8) {
                bytes.push_back('\0');
                used = 0;
            }
            if ((value >> bit) & 1u) {
                bytes.back() = static_cast<char>(bytes.back() | (1 << used));
            }
            ++used;
        }
    }
    return bytes;
}

std::uint64_t physical(std::uint64_t logical) {
    return logical / kPageData * kPage + logical % kPageData;
}

void padTo4(std::string& packet) {
    while (packet.size() % 4 != 0) {
        packet.push_back('\0');
    }
}

/// The packets of one compressed vector: an empty packet, data packets that carry up to
/// `chunkBytes` of every stream each (so values cross packet boundaries), an index packet.
std::string packets(const TestScan& scan) {
    std::string out;
    std::string empty;
    appendBytes<std::uint8_t>(empty, 2);
    appendBytes<std::uint8_t>(empty, 0);
    appendBytes<std::uint16_t>(empty, 7);
    empty.resize(8, '\0');
    out += empty;

    std::vector<std::string> streams;
    for (const TestField& field : scan.fields) {
        streams.push_back(bitPack(field));
    }
    std::vector<std::size_t> done(streams.size(), 0);
    auto remaining = [&] {
        for (std::size_t s = 0; s < streams.size(); ++s) {
            if (done[s] < streams[s].size()) {
                return true;
            }
        }
        return false;
    };
    while (remaining()) {
        std::string header, body;
        for (std::size_t s = 0; s < streams.size(); ++s) {
            const std::size_t take = std::min(scan.chunkBytes, streams[s].size() - done[s]);
            appendBytes<std::uint16_t>(header, static_cast<std::uint16_t>(take));
            body += streams[s].substr(done[s], take);
            done[s] += take;
        }
        std::string packet;
        appendBytes<std::uint8_t>(packet, scan.packetType.value_or(1));
        appendBytes<std::uint8_t>(packet, 0);
        appendBytes<std::uint16_t>(packet, 0);  // length, set below
        appendBytes<std::uint16_t>(packet, static_cast<std::uint16_t>(streams.size()));
        packet += header + body;
        padTo4(packet);
        const auto lengthMinus1 = static_cast<std::uint16_t>(packet.size() - 1);
        std::memcpy(packet.data() + 2, &lengthMinus1, 2);
        out += packet;
    }

    std::string index;  // no entries: type, reserved, length - 1, count, level, 9 reserved
    appendBytes<std::uint8_t>(index, 0);
    appendBytes<std::uint8_t>(index, 0);
    appendBytes<std::uint16_t>(index, 15);
    index.resize(16, '\0');
    return out + index;
}

std::string scanXml(const TestScan& scan, std::uint64_t sectionPhysical) {
    std::string prototype;
    for (const TestField& field : scan.fields) {
        prototype += fmt::format("<{} {}/>", field.name, field.xml);
    }
    const std::string count = scan.recordCount.value_or(
        std::to_string(scan.fields.empty() ? 0 : scan.fields[0].raw.size()));
    return fmt::format(
        R"(<vectorChild type="Structure"><name type="String"><![CDATA[scan]]></name>{})"
        R"(<points type="CompressedVector" fileOffset="{}" recordCount="{}">)"
        R"(<prototype type="Structure">{}</prototype>)"
        R"(<codecs type="Vector" allowHeterogeneousChildren="1"/></points></vectorChild>)",
        scan.extraXml, scan.fileOffset.value_or(std::to_string(sectionPhysical)), count, prototype);
}

/// A whole E57 file: header, one compressed vector section per scan, the XML (or `xml`, used
/// as the whole XML section), all cut into checksummed pages.
std::string writeE57(const std::vector<TestScan>& scans,
                     const std::optional<std::string>& xml = std::nullopt) {
    std::string logical(48, '\0');
    std::string children;
    for (const TestScan& scan : scans) {
        const std::uint64_t sectionStart = logical.size();
        const std::string body = packets(scan);
        std::string section;
        appendBytes<std::uint8_t>(section, 1);
        section.resize(8, '\0');
        appendBytes<std::uint64_t>(section, 32 + body.size());
        appendBytes<std::uint64_t>(section, physical(sectionStart + 32));
        appendBytes<std::uint64_t>(section, 0);
        logical += section + body;
        children += scanXml(scan, physical(sectionStart));
    }
    const std::string text = xml.value_or(
        R"(<?xml version="1.0" encoding="UTF-8"?>)"
        R"(<e57Root type="Structure" xmlns="http://www.astm.org/COMMIT/E57/2010-e57-v1.0">)"
        R"(<formatName type="String"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>)"
        R"(<versionMajor type="Integer">1</versionMajor><versionMinor type="Integer"/>)"
        R"(<data3D type="Vector" allowHeterogeneousChildren="1">)" +
        children + R"(</data3D></e57Root>)");
    const std::uint64_t xmlStart = logical.size();
    logical += text;

    const std::size_t pages = (logical.size() + kPageData - 1) / kPageData;
    logical.resize(pages * kPageData, '\0');
    std::string header;
    header += "ASTM-E57";
    appendBytes<std::uint32_t>(header, 1);
    appendBytes<std::uint32_t>(header, 0);
    appendBytes<std::uint64_t>(header, pages * kPage);
    appendBytes<std::uint64_t>(header, physical(xmlStart));
    appendBytes<std::uint64_t>(header, text.size());
    appendBytes<std::uint64_t>(header, kPage);
    logical.replace(0, header.size(), header);

    std::string file;
    for (std::size_t page = 0; page < pages; ++page) {
        const char* data = logical.data() + page * kPageData;
        file.append(data, kPageData);
        appendBytes<std::uint32_t>(file, bitwiseCrc32c(data, kPageData), true);  // big-endian
    }
    return file;
}

/// Overwrites a header field and recomputes the first page's checksum.
void patchHeader(std::string& file, std::size_t offset, std::uint64_t value) {
    std::memcpy(file.data() + offset, &value, sizeof(value));
    const std::uint32_t crc = bitwiseCrc32c(file.data(), kPageData);
    for (int i = 0; i < 4; ++i) {
        file[kPageData + i] = static_cast<char>(crc >> (8 * (3 - i)));
    }
}

/// scripts/fuzz.sh seeds the E57 fuzzer with the files these tests build: with
/// SUBSCAN_E57_SEEDS set, valid ones are also written there.
void saveFuzzSeed(const std::string& name, const std::string& bytes) {
    if (const char* directory = std::getenv("SUBSCAN_E57_SEEDS"); directory && *directory) {
        std::ofstream(std::filesystem::path(directory) / name, std::ios::binary) << bytes;
    }
}

PointCloud read(const std::string& file, ReadContext& context) {
    return readE57(test::asBytes(file), context);
}

PointCloud read(const std::string& file) {
    ReadContext context;
    return read(file, context);
}

std::string readError(const std::string& file) {
    try {
        read(file);
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "no error";
    return {};
}

/// One sentence on one line, as the loader prefixes it with the file name.
void expectOneSentence(const std::string& message) {
    EXPECT_FALSE(message.empty());
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(E57ReaderTest, Crc32cGivesTheStandardCheckValue) {
    // The check value of CRC-32C (Castagnoli), e.g. RFC 3720 appendix B.4 and the CRC catalogue.
    const std::string text = "123456789";
    EXPECT_EQ(crc32c(test::asBytes(text)), 0xE3069283u);
    EXPECT_EQ(bitwiseCrc32c(text.data(), text.size()), 0xE3069283u);
    EXPECT_EQ(crc32c({}), 0u);
}

/// 700 records: x ScaledInteger (14 bits), an unused 10-bit field, y double, z Integer (3 bits),
/// intensity single; 37-byte chunks put values across packet boundaries, and the 5,600 bytes
/// of y cross several page boundaries.
struct MixedScan {
    std::vector<std::int64_t> xStored, rows, z;
    std::vector<double> y;
    std::vector<float> intensity;
    static constexpr double kScale = 0.001, kOffset = 1.5;

    MixedScan() {
        for (int i = 0; i < 700; ++i) {
            xStored.push_back((i * 37) % 10001 - 5000);
            rows.push_back((i * 7) % 1001);
            y.push_back(std::sin(i * 0.1) * 3.0 + 1e-9 * i);
            z.push_back(i % 8 - 3);
            intensity.push_back(static_cast<float>(i) * 0.25f);
        }
    }
    TestScan scan() const {
        TestScan s;
        s.fields = {scaledField("cartesianX", -5000, 5000, kScale, kOffset, xStored),
                    integerField("rowIndex", 0, 1000, rows), doubleField("cartesianY", y),
                    integerField("cartesianZ", -3, 4, z), singleField("intensity", intensity)};
        s.chunkBytes = 37;
        return s;
    }
};

TEST(E57ReaderTest, BitPackedAndFloatFieldsAcrossPacketsAndPages) {
    const MixedScan points;
    const std::string file = writeE57({points.scan()});
    ASSERT_GT(file.size(), 6 * kPage);
    saveFuzzSeed("mixed.e57", file);
    ReadContext context;
    std::vector<double> progress;
    context.progress = [&](double done) { progress.push_back(done); };
    const PointCloud cloud = read(file, context);
    EXPECT_EQ(context.formatDetail, "E57 1.0, 1 scan, cartesian ScaledInteger");
    EXPECT_THAT(context.warnings, IsEmpty());
    ASSERT_EQ(cloud.size(), 700u);
    ASSERT_TRUE(cloud.hasIntensities());
    EXPECT_FALSE(cloud.hasColors());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        test::expectPosition(cloud, i, points.xStored[i] * MixedScan::kScale + MixedScan::kOffset,
                             points.y[i], static_cast<double>(points.z[i]));
        EXPECT_EQ(cloud.intensities[i], points.intensity[i]) << i;
    }
    ASSERT_FALSE(progress.empty());
    EXPECT_GT(progress.size(), 2u);  // once per data packet, not only at the end
    EXPECT_DOUBLE_EQ(progress.back(), 1.0);
}

TEST(E57ReaderTest, LoaderDetectsAndNamesTheFormat) {
    const std::string file = writeE57({MixedScan().scan()});
    const LoadedScan scan = test::decode(file, "scan.bin");
    EXPECT_EQ(scan.format, "e57");
    EXPECT_EQ(scan.formatDetail, "E57 1.0, 1 scan, cartesian ScaledInteger");
    EXPECT_EQ(scan.cloud.size(), 700u);
}

TEST(E57ReaderTest, ValuesAsWideAsSixtyFourBits) {
    // The full int64 range takes 64 bits; 63 and 33 bits leave values across byte boundaries.
    // Scales keep every coordinate within +-10, where the cloud's floats resolve ~1e-6.
    const std::int64_t lo = std::numeric_limits<std::int64_t>::min();
    const std::int64_t hi = std::numeric_limits<std::int64_t>::max();
    const std::int64_t y62 = std::int64_t{1} << 62;
    const std::int64_t z33 = (std::int64_t{1} << 33) - 1;
    TestScan scan;
    scan.fields = {scaledField("cartesianX", lo, hi, 1e-18, 0.0, {lo, 0, hi, 12345678901234567}),
                   scaledField("cartesianY", -y62, y62, 1e-18, 0.0, {-y62, 1, y62, 3}),
                   scaledField("cartesianZ", 0, z33, 1e-9, 0.0, {0, 1, z33, 5})};
    EXPECT_EQ(scan.fields[0].bits, 64u);
    EXPECT_EQ(scan.fields[1].bits, 64u);  // -2^62..2^62 is 2^63 + 1 values
    EXPECT_EQ(scan.fields[2].bits, 33u);
    scan.fields.push_back(
        integerField("cartesianInvalidState", 0, (std::int64_t{1} << 62) - 1, {0, 0, 0, 0}));
    EXPECT_EQ(scan.fields[3].bits, 62u);
    scan.chunkBytes = 3;
    const PointCloud cloud = read(writeE57({scan}));
    ASSERT_EQ(cloud.size(), 4u);
    test::expectPosition(cloud, 0, static_cast<double>(lo) * 1e-18,
                         static_cast<double>(-y62) * 1e-18, 0.0);
    test::expectPosition(cloud, 2, static_cast<double>(hi) * 1e-18,
                         static_cast<double>(y62) * 1e-18, static_cast<double>(z33) * 1e-9);
    test::expectPosition(cloud, 3, static_cast<double>(12345678901234567) * 1e-18, 3e-18, 5e-9);
}

TEST(E57ReaderTest, TwoScansAreJoinedEachWithItsPose) {
    const std::vector<double> xs{1.0, 0.0, 2.0}, ys{0.0, 1.0, 0.5}, zs{0.0, 0.0, -1.0};
    TestScan first;
    first.fields = {doubleField("cartesianX", xs), doubleField("cartesianY", ys),
                    doubleField("cartesianZ", zs)};
    TestScan second = first;
    // 90 degrees about z, written unnormalised (scaled by 2): the reader normalises it.
    const double c = 2.0 * std::cos(std::numbers::pi / 4), s = 2.0 * std::sin(std::numbers::pi / 4);
    second.extraXml = fmt::format(
        R"(<pose type="Structure"><rotation type="Structure"><w type="Float">{:.17g}</w>)"
        R"(<x type="Float"/><y type="Float">0</y><z type="Float">{:.17g}</z></rotation>)"
        R"(<translation type="Structure"><x type="Float">10</x><y type="Float">20</y>)"
        R"(<z type="Float">30</z></translation></pose>)",
        c, s);
    const std::string file = writeE57({first, second});
    saveFuzzSeed("two-scans-pose.e57", file);
    ReadContext context;
    const PointCloud cloud = read(file, context);
    EXPECT_EQ(context.formatDetail, "E57 1.0, 2 scans, cartesian Float (double)");
    ASSERT_EQ(cloud.size(), 6u);
    for (std::size_t i = 0; i < 3; ++i) {
        test::expectPosition(cloud, i, xs[i], ys[i], zs[i]);
        // (x, y, z) turned to (-y, x, z), then moved.
        test::expectPosition(cloud, 3 + i, -ys[i] + 10.0, xs[i] + 20.0, zs[i] + 30.0);
    }
}

TEST(E57ReaderTest, SphericalCoordinatesWithInvalidStates) {
    const std::vector<double> range{2.0, 3.0, 1.0, 5.0};
    const std::vector<double> azimuth{0.0, 0.5, 1.0, -2.0};
    const std::vector<double> elevation{0.0, 0.25, -0.5, 1.2};
    TestScan scan;
    scan.fields = {doubleField("sphericalRange", range), singleField("unused", {1, 2, 3, 4}),
                   doubleField("sphericalAzimuth", azimuth),
                   doubleField("sphericalElevation", elevation),
                   // 1: direction only, 2: nothing measured; both have no position.
                   integerField("sphericalInvalidState", 0, 2, {0, 1, 0, 2})};
    const std::string file = writeE57({scan});
    saveFuzzSeed("spherical.e57", file);
    ReadContext context;
    const PointCloud cloud = read(file, context);
    EXPECT_EQ(context.formatDetail, "E57 1.0, 1 scan, spherical Float (double)");
    EXPECT_THAT(context.warnings, Contains(HasSubstr("skipped 2 of 4 E57 points marked invalid")));
    ASSERT_EQ(cloud.size(), 2u);
    std::size_t kept = 0;
    for (std::size_t i : {0u, 2u}) {
        const double r = range[i], az = azimuth[i], el = elevation[i];
        test::expectPosition(cloud, kept++, r * std::cos(el) * std::cos(az),
                             r * std::cos(el) * std::sin(az), r * std::sin(el));
    }
}

TEST(E57ReaderTest, CartesianInvalidStateDropsPointsAndAllInvalidIsAnError) {
    TestScan scan;
    scan.fields = {doubleField("cartesianX", {1, 2, 3}), doubleField("cartesianY", {4, 5, 6}),
                   doubleField("cartesianZ", {7, 8, 9}),
                   integerField("cartesianInvalidState", 0, 2, {2, 0, 1})};
    const PointCloud cloud = read(writeE57({scan}));
    ASSERT_EQ(cloud.size(), 1u);
    test::expectPosition(cloud, 0, 2, 5, 8);

    scan.fields[3] = integerField("cartesianInvalidState", 0, 2, {2, 1, 2});
    const std::string message = readError(writeE57({scan}));
    EXPECT_THAT(message, HasSubstr("all 3 points of the E57 file are marked invalid"));
    expectOneSentence(message);
}

TEST(E57ReaderTest, ColourLimitsMapToBytesAndInvalidFlagsAreHonoured) {
    TestScan scan;
    scan.fields = {doubleField("cartesianX", {0, 1, 2, 3}),
                   doubleField("cartesianY", {0, 0, 0, 0}),
                   doubleField("cartesianZ", {0, 0, 0, 0}),
                   integerField("colorRed", 0, 4095, {0, 4095, 2048, 100}),
                   integerField("colorGreen", 0, 4095, {4095, 0, 1, 100}),
                   integerField("colorBlue", 0, 4095, {16, 32, 4000, 100}),
                   integerField("isColorInvalid", 0, 1, {0, 0, 0, 1}),
                   integerField("intensity", 0, 1000, {10, 20, 30, 40}),
                   integerField("isIntensityInvalid", 0, 1, {0, 1, 0, 0})};
    scan.chunkBytes = 5;
    // Limits narrower than the fields' bounds: they, not the field bounds, decide the mapping.
    scan.extraXml =
        R"(<colorLimits type="Structure"><colorRedMinimum type="Integer">0</colorRedMinimum>)"
        R"(<colorRedMaximum type="Integer">4095</colorRedMaximum>)"
        R"(<colorGreenMinimum type="Integer">0</colorGreenMinimum>)"
        R"(<colorGreenMaximum type="Integer">4095</colorGreenMaximum>)"
        R"(<colorBlueMinimum type="Integer">16</colorBlueMinimum>)"
        R"(<colorBlueMaximum type="Integer">271</colorBlueMaximum></colorLimits>)";
    const std::string file = writeE57({scan});
    saveFuzzSeed("colour.e57", file);
    const PointCloud cloud = read(file);
    ASSERT_EQ(cloud.size(), 4u);
    ASSERT_TRUE(cloud.hasColors());
    ASSERT_TRUE(cloud.hasIntensities());
    // round(v * 255 / 4095): 2048 -> 127.5 -> 128; blue (v - 16) over 255 steps, clamped.
    EXPECT_EQ(cloud.colors[0], (Rgba8{0, 255, 0, 255}));
    EXPECT_EQ(cloud.colors[1], (Rgba8{255, 0, 16, 255}));
    EXPECT_EQ(cloud.colors[2], (Rgba8{128, 0, 255, 255}));
    EXPECT_EQ(cloud.colors[3], (Rgba8{200, 200, 200, 255}));  // isColorInvalid: neutral grey
    EXPECT_EQ(cloud.intensities, (std::vector<float>{10, 0, 30, 40}));  // invalid -> 0

    // Without colorLimits the fields' own minimum and maximum are the limits.
    scan.extraXml.clear();
    scan.fields[3] = integerField("colorRed", 0, 255, {0, 255, 128, 1});
    scan.fields[4] = integerField("colorGreen", 10, 20, {10, 20, 15, 11});
    scan.fields[5] = integerField("colorBlue", 0, 255, {7, 8, 9, 1});
    const PointCloud bounded = read(writeE57({scan}));
    EXPECT_EQ(bounded.colors[0], (Rgba8{0, 0, 7, 255}));
    EXPECT_EQ(bounded.colors[1], (Rgba8{255, 255, 8, 255}));
    EXPECT_EQ(bounded.colors[2], (Rgba8{128, 128, 9, 255}));  // 127.5 rounds up
}

TEST(E57ReaderTest, ColourBeyondEightBitsIsMarkedCut) {
    // convert warns of it as of LAS colour; it cut 16-bit E57 colour to 8 bits without a word.
    const auto cut = [](const std::vector<std::int64_t>& red, std::int64_t maximum) {
        TestScan scan;
        scan.fields = {doubleField("cartesianX", {0, 1, 2}),
                       doubleField("cartesianY", {0, 0, 0}),
                       doubleField("cartesianZ", {0, 0, 0}),
                       integerField("colorRed", 0, maximum, red),
                       integerField("colorGreen", 0, maximum, {0, 0, 0}),
                       integerField("colorBlue", 0, maximum, {0, 0, 0}),
                       integerField("isColorInvalid", 0, 1, {0, 0, 1})};
        return read(writeE57({scan})).colorCutTo8Bits;
    };
    EXPECT_TRUE(cut({65535, 1000, 0}, 65535));
    EXPECT_TRUE(cut({4095, 2048, 0}, 4095));
    // Values that 8 bits give back (8-bit ones times 257), or limits of 8 bits, lose nothing.
    EXPECT_FALSE(cut({65535, 257 * 100, 0}, 65535));
    EXPECT_FALSE(cut({255, 17, 0}, 255));
    // The colour of a point marked isColorInvalid is not the point's.
    EXPECT_FALSE(cut({65535, 0, 1000}, 65535));
}

TEST(E57ReaderTest, ColourKeptOnlyWhenEveryScanHasIt) {
    TestScan plain;
    plain.fields = {doubleField("cartesianX", {1}), doubleField("cartesianY", {2}),
                    doubleField("cartesianZ", {3})};
    TestScan colored = plain;
    for (const char* name : {"colorRed", "colorGreen", "colorBlue"}) {
        colored.fields.push_back(integerField(name, 0, 255, {9}));
    }
    ReadContext context;
    const PointCloud cloud = read(writeE57({plain, colored}), context);
    EXPECT_EQ(cloud.size(), 2u);
    EXPECT_FALSE(cloud.hasColors());
    EXPECT_THAT(context.warnings, Contains(HasSubstr("only 1 of the 2 E57 scans have colour")));
}

TEST(E57ReaderTest, ConstantFieldsTakeNoBits) {
    TestScan scan;
    scan.fields = {doubleField("cartesianX", {1, 2, 3}),
                   integerField("cartesianY", 7, 7, {7, 7, 7}),
                   scaledField("cartesianZ", 4, 4, 0.5, 1.0, {4, 4, 4})};
    EXPECT_EQ(scan.fields[1].bits, 0u);
    const PointCloud cloud = read(writeE57({scan}));
    ASSERT_EQ(cloud.size(), 3u);
    test::expectPosition(cloud, 2, 3, 7, 3);
}

// ---------------------------------------------------------------------------------------------
// Bad input: one sentence each, naming what is wrong.

TestScan smallScan() {
    TestScan scan;
    std::vector<std::int64_t> values;
    for (int i = 0; i < 300; ++i) {
        values.push_back(i * 1000 - 150000);
    }
    scan.fields = {scaledField("cartesianX", -2147483648LL, 2147483647LL, 1e-3, 0, values),
                   scaledField("cartesianY", -2147483648LL, 2147483647LL, 1e-3, 0, values),
                   scaledField("cartesianZ", -2147483648LL, 2147483647LL, 1e-3, 0, values)};
    return scan;
}

TEST(E57ReaderTest, BadPageChecksumNamesThePageOffset) {
    std::string file = writeE57({smallScan()});
    ASSERT_GT(file.size(), 3 * kPage);
    file[2 * kPage + 100] ^= 0x10;
    const std::string message = readError(file);
    EXPECT_THAT(message, AllOf(HasSubstr("page at byte offset 2048"), HasSubstr("CRC-32C")));
    expectOneSentence(message);

    // A checksum stored little-endian is refused too: the standard's order is big-endian.
    std::string swapped = writeE57({smallScan()});
    std::reverse(swapped.begin() + kPageData, swapped.begin() + kPage);
    EXPECT_THAT(readError(swapped), HasSubstr("page at byte offset 0 "));
}

TEST(E57ReaderTest, TruncatedFiles) {
    const std::string file = writeE57({smallScan()});
    EXPECT_THAT(readError(file.substr(0, file.size() - kPage)),
                AllOf(HasSubstr("its E57 header gives"), HasSubstr("truncated")));
    EXPECT_THAT(readError(file.substr(0, 20)), HasSubstr("fewer than the 48-byte E57 file header"));
    EXPECT_THAT(readError("ASTM-E5"), HasSubstr("E57 signature"));
    for (const std::size_t size : {std::size_t{0}, std::size_t{8}, std::size_t{47}, kPage - 1,
                                   2 * kPage + 1, file.size() - 1}) {
        expectOneSentence(readError(file.substr(0, size)));
    }
}

TEST(E57ReaderTest, HeaderFieldsAreCheckedAgainstTheFile) {
    const std::string valid = writeE57({smallScan()});
    std::string file = valid;
    patchHeader(file, 40, 2048);
    EXPECT_THAT(readError(file), HasSubstr("page size of 2048 bytes"));

    file = valid;
    patchHeader(file, 24, valid.size() + 10);
    EXPECT_THAT(readError(file), HasSubstr("XML section"));
    file = valid;
    patchHeader(file, 32, valid.size());  // XML length past the end
    EXPECT_THAT(readError(file), HasSubstr("lies outside the file"));
    file = valid;
    patchHeader(file, 24, 1022);  // inside the first page's checksum
    EXPECT_THAT(readError(file), HasSubstr("XML section"));

    file = valid;
    patchHeader(file, 16, 1000);
    EXPECT_THAT(readError(file), HasSubstr("not a whole number of 1024-byte pages"));
    file = valid;
    patchHeader(file, 8, 2);  // major version 2, minor 0
    EXPECT_THAT(readError(file), HasSubstr("E57 version 2.0 is not supported"));
}

TEST(E57ReaderTest, XmlProblems) {
    const std::string head = R"(<?xml version="1.0"?><e57Root type="Structure">)";
    EXPECT_THAT(readError(writeE57({}, head + "</e57Root>")), HasSubstr("no data3D element"));
    EXPECT_THAT(readError(writeE57({}, head + R"(<data3D type="Vector"/></e57Root>)")),
                HasSubstr("data3D vector is empty"));
    EXPECT_THAT(readError(writeE57({}, head + "<data3D>")), HasSubstr("not well-formed XML"));
    EXPECT_THAT(readError(writeE57({}, "<other/>")), HasSubstr("no e57Root element"));

    TestScan noCoordinates;
    noCoordinates.fields = {doubleField("intensity", {1})};
    EXPECT_THAT(readError(writeE57({noCoordinates})), HasSubstr("neither cartesianX/Y/Z"));
    TestScan partial = smallScan();
    partial.fields.pop_back();
    EXPECT_THAT(readError(writeE57({partial})), HasSubstr("no cartesianZ field"));
    TestScan badPose = smallScan();
    badPose.extraXml = R"(<pose type="Structure"><rotation type="Structure"><w type="Float"/>)"
                       R"(</rotation></pose>)";
    EXPECT_THAT(readError(writeE57({badPose})), HasSubstr("is not a rotation"));
    TestScan badNumber = smallScan();
    badNumber.recordCount = "many";
    EXPECT_THAT(readError(writeE57({badNumber})), HasSubstr("recordCount 'many'"));
}

TEST(E57ReaderTest, ImpossibleBitWidthIsRefused) {
    TestScan scan = smallScan();
    // A maximum beyond int64 would need a value wider than 64 bits.
    scan.fields[1].xml = R"(type="Integer" minimum="0" maximum="100000000000000000000")";
    const std::string message = readError(writeE57({scan}));
    EXPECT_THAT(message, AllOf(HasSubstr("field cartesianY"), HasSubstr("more than 64 bits")));
    expectOneSentence(message);

    scan.fields[1].xml = R"(type="Integer" minimum="5" maximum="4")";
    EXPECT_THAT(readError(writeE57({scan})), HasSubstr("greater than its maximum"));
}

TEST(E57ReaderTest, RecordCountMustMatchTheStreams) {
    TestScan scan = smallScan();
    scan.recordCount = "301";
    std::string message = readError(writeE57({scan}));
    EXPECT_THAT(message, AllOf(HasSubstr("declares 301 records"), HasSubstr("holds only 300")));
    expectOneSentence(message);

    scan.recordCount = "290";  // ten 32-bit values left over: no writer pads that much
    message = readError(writeE57({scan}));
    EXPECT_THAT(message, AllOf(HasSubstr("declares 290 records"), HasSubstr("320 bits more")));

    scan.recordCount = "999999";
    EXPECT_THAT(readError(writeE57({scan})), HasSubstr("more than its"));
}

TEST(E57ReaderTest, ValueBeyondItsMaximumIsRefused) {
    TestScan scan = smallScan();
    // 0..4 takes 3 bits, so 7 can be written but is not a valid value.
    scan.fields.push_back(integerField("cartesianInvalidState", 0, 4, {}));
    scan.fields.back().raw.assign(300, 0);
    scan.fields.back().raw[123] = 7;
    EXPECT_THAT(readError(writeE57({scan})),
                HasSubstr("field cartesianInvalidState of scan 1 holds a value outside"));
}

TEST(E57ReaderTest, SectionAndPacketProblems) {
    TestScan scan = smallScan();
    scan.fileOffset = "99999999";
    std::string message = readError(writeE57({scan}));
    EXPECT_THAT(message, AllOf(HasSubstr("byte offset 99999999"), HasSubstr("outside the file")));
    expectOneSentence(message);
    scan.fileOffset = "1020";  // inside a checksum
    EXPECT_THAT(readError(writeE57({scan})), HasSubstr("outside the file"));
    scan.fileOffset = "0";  // the file header, not a section
    EXPECT_THAT(readError(writeE57({scan})), HasSubstr("has id 65, not the id 1"));

    scan = smallScan();
    scan.packetType = 7;
    EXPECT_THAT(readError(writeE57({scan})), HasSubstr("has the unknown type 7"));

    // A section that claims to run past the end of the file: patch its length field.
    std::string file = writeE57({smallScan()});
    const std::uint64_t huge = 1u << 30;
    std::memcpy(file.data() + 48 + 8, &huge, 8);
    const std::uint32_t crc = bitwiseCrc32c(file.data(), kPageData);
    for (int i = 0; i < 4; ++i) {
        file[kPageData + i] = static_cast<char>(crc >> (8 * (3 - i)));
    }
    EXPECT_THAT(readError(file), HasSubstr("more than the file holds after it"));
}

TEST(E57ReaderTest, MangledFilesGiveErrorsNotCrashes) {
    // Every 7th byte of header, packets and XML, changed in turn, with checksums redone:
    // each outcome is a cloud or a subscan::Error (ASan builds check the bounds).
    const std::string valid = writeE57({MixedScan().scan()});
    const std::size_t logicalSize = valid.size() / kPage * kPageData;
    for (std::size_t offset = 0; offset < logicalSize; offset += 7) {
        std::string logical;
        for (std::size_t page = 0; page < valid.size() / kPage; ++page) {
            logical.append(valid, page * kPage, kPageData);
        }
        logical[offset] = static_cast<char>(logical[offset] ^ 0x5A);
        std::string file;
        for (std::size_t page = 0; page < valid.size() / kPage; ++page) {
            file.append(logical, page * kPageData, kPageData);
            appendBytes<std::uint32_t>(file, bitwiseCrc32c(file.data() + page * kPage, kPageData),
                                       true);
        }
        try {
            read(file);
        } catch (const Error& error) {
            expectOneSentence(error.what());
        }
    }
}

}  // namespace
}  // namespace subscan
