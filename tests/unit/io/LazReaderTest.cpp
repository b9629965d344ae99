// LAZ without real files: the library's arithmetic encoder and integer compressor (the mirrors
// of the decoders) build, field by field here, small files of the variants no shared file has —
// point formats 0 with BYTE extra bytes, 7 and 8 with BYTE14, chunks of one point, variable
// chunks — and the malformed cases. The entropy models are the decoder's own (shared by coder and
// decoder in LASzip too); the real files in LazDataTest check them against an independent
// encoder.
#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasReader.h"
#include "io/ReadContext.h"
#include "io/laz/ArithmeticDecoder.h"
#include "io/laz/ArithmeticEncoder.h"
#include "io/laz/IntegerCompressor.h"
#include "io/laz/IntegerDecompressor.h"
#include "io/laz/ItemCoding.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using laz::BitModel;
using laz::SymbolModel;
using test::appendBytes;
using ::testing::HasSubstr;

using Encoder = laz::ArithmeticEncoder;
using laz::IntegerCompressor;

/// A finished stream's bytes as the test's file builders hold them.
std::string finished(Encoder& encoder) {
    const std::vector<std::byte> bytes = encoder.finish();
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

TEST(LazReaderTest, DecoderReadsWhatTheEncoderWrote) {
    Encoder encoder;
    BitModel bit;
    SymbolModel small(5);
    SymbolModel large(300);  // above 16 symbols: the decoder's table path
    IntegerCompressor integers(32, 3);
    IntegerCompressor shorts(16, 1);
    std::uint32_t state = 12345;
    const auto next = [&] { return state = state * 1664525u + 1013904223u; };
    struct Step {
        std::uint32_t bit, small, large, raw;
        std::int32_t integer;
        std::int32_t shortValue;
    };
    std::vector<Step> steps(3000);
    for (std::size_t i = 0; i < steps.size(); ++i) {
        Step& s = steps[i];
        // Skewed values, so models adapt, and rare extremes (k up to 32, 16-bit wrap).
        s.bit = (next() >> 7) % 7 == 0 ? 1 : 0;
        s.small = (next() >> 9) % 3;
        s.large = (next() >> 3) % (i % 100 == 0 ? 300 : 20);
        s.raw = next() >> 9;
        s.integer = i % 500 == 0 ? static_cast<std::int32_t>(next())
                                 : static_cast<std::int32_t>(next() % 41) - 20;
        s.shortValue = static_cast<std::int32_t>(next() % 65536);
        encoder.encodeBit(bit, s.bit);
        encoder.encodeSymbol(small, s.small);
        encoder.encodeSymbol(large, s.large);
        encoder.writeBits(23, s.raw);
        integers.compress(encoder, 7, s.integer, i % 3);
        shorts.compress(encoder, 60000, s.shortValue);
    }
    const std::string bytes = finished(encoder);

    laz::ArithmeticDecoder decoder(test::asBytes(bytes));
    BitModel bitIn;
    SymbolModel smallIn(5);
    SymbolModel largeIn(300);
    laz::IntegerDecompressor integersIn(32, 3);
    laz::IntegerDecompressor shortsIn(16, 1);
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const Step& s = steps[i];
        ASSERT_EQ(decoder.decodeBit(bitIn), s.bit) << i;
        ASSERT_EQ(decoder.decodeSymbol(smallIn), s.small) << i;
        ASSERT_EQ(decoder.decodeSymbol(largeIn), s.large) << i;
        ASSERT_EQ(decoder.readBits(23), s.raw) << i;
        ASSERT_EQ(integersIn.decompress(decoder, 7, i % 3), s.integer) << i;
        ASSERT_EQ(shortsIn.decompress(decoder, 60000), s.shortValue) << i;
    }
    // The padding keeps the decoder inside the stream: decoding everything read exactly the
    // encoded bytes. A stream cut short is an error, not a read past its end.
    EXPECT_THROW(laz::ArithmeticDecoder(test::asBytes(std::string_view(bytes).substr(0, 3))),
                 Error);
    laz::ArithmeticDecoder cut(test::asBytes(std::string_view(bytes).substr(0, bytes.size() / 2)));
    BitModel bitCut;
    SymbolModel smallCut(5);
    SymbolModel largeCut(300);
    EXPECT_THROW(
        for (std::size_t i = 0; i < steps.size(); ++i) {
            cut.decodeBit(bitCut);
            cut.decodeSymbol(smallCut);
            cut.decodeSymbol(largeCut);
            cut.readBits(23);
        },
        Error);
}

// --- Building LAZ files -------------------------------------------------------------------

struct Item {
    std::uint16_t type, size, version;
};

/// A LAS 1.4 (or 1.2) header, one laszip VLR, the point data and the chunk table.
struct LazFile {
    int pointFormat = 0;
    int minorVersion = 2;
    std::uint16_t compressor = 2;
    std::uint32_t chunkSize = 50000;  // 0xFFFFFFFF: variable
    std::vector<Item> items;
    std::vector<std::string> chunks;
    std::vector<std::uint32_t> chunkPoints;
    std::uint64_t pointCount = 0;
    bool copcInfoVlr = false;  // a "copc" info VLR (zeros, for the test to fill) comes first

    std::size_t recordLength() const {
        std::size_t length = 0;
        for (const Item& item : items) {
            length += item.size;
        }
        return length;
    }

    std::string chunkTable() const {
        std::string table;
        appendBytes<std::uint32_t>(table, 0);
        appendBytes<std::uint32_t>(table, static_cast<std::uint32_t>(chunks.size()));
        Encoder encoder;
        IntegerCompressor integers(32, 2);
        std::int32_t lastCount = 0;
        std::int32_t lastSize = 0;
        for (std::size_t i = 0; i < chunks.size(); ++i) {
            if (chunkSize == 0xFFFFFFFFu) {
                integers.compress(encoder, lastCount, static_cast<std::int32_t>(chunkPoints[i]), 0);
                lastCount = static_cast<std::int32_t>(chunkPoints[i]);
            }
            const auto size = static_cast<std::int32_t>(chunks[i].size());
            integers.compress(encoder, lastSize, size, 1);
            lastSize = size;
        }
        return table + finished(encoder);
    }

    std::string bytes() const {
        const std::size_t headerSize = minorVersion >= 4 ? 375 : 227;
        std::string vlr(54, '\0');
        std::memcpy(vlr.data() + 2, "laszip encoded", 14);
        std::string payload;
        appendBytes<std::uint16_t>(payload, compressor);
        appendBytes<std::uint16_t>(payload, 0);  // coder
        payload += std::string("\x03\x04", 2);   // LASzip 3.4
        appendBytes<std::uint16_t>(payload, 0);  // revision
        appendBytes<std::uint32_t>(payload, 0);  // options
        appendBytes<std::uint32_t>(payload, chunkSize);
        appendBytes<std::int64_t>(payload, -1);
        appendBytes<std::int64_t>(payload, -1);
        appendBytes<std::uint16_t>(payload, static_cast<std::uint16_t>(items.size()));
        for (const Item& item : items) {
            appendBytes(payload, item.type);
            appendBytes(payload, item.size);
            appendBytes(payload, item.version);
        }
        const std::uint16_t recordId = 22204;
        std::memcpy(vlr.data() + 18, &recordId, 2);
        const auto payloadSize = static_cast<std::uint16_t>(payload.size());
        std::memcpy(vlr.data() + 20, &payloadSize, 2);
        vlr += payload;
        if (copcInfoVlr) {
            std::string info(54 + 160, '\0');
            std::memcpy(info.data() + 2, "copc", 4);
            info[18] = 1;  // record 1
            info[20] = static_cast<char>(160);
            vlr = info + vlr;
        }

        const std::size_t pointData = headerSize + vlr.size();
        std::string points;
        for (const std::string& chunk : chunks) {
            points += chunk;
        }
        std::string file(headerSize, '\0');
        std::memcpy(file.data(), "LASF", 4);
        file[24] = 1;
        file[25] = static_cast<char>(minorVersion);
        const auto put = [&](std::size_t offset, auto value) {
            std::memcpy(file.data() + offset, &value, sizeof(value));
        };
        put(94, static_cast<std::uint16_t>(headerSize));
        put(96, static_cast<std::uint32_t>(pointData));
        put(100, std::uint32_t{copcInfoVlr ? 2u : 1u});
        put(104, static_cast<std::uint8_t>(pointFormat | 0x80));
        put(105, static_cast<std::uint16_t>(recordLength()));
        put(107, static_cast<std::uint32_t>(pointFormat < 6 ? pointCount : 0));
        for (int axis = 0; axis < 3; ++axis) {
            put(131 + 8 * axis, 0.001);
        }
        if (minorVersion >= 4) {
            put(247, pointCount);
        }
        file += vlr;
        appendBytes<std::int64_t>(file, static_cast<std::int64_t>(pointData + 8 + points.size()));
        return file + points + chunkTable();
    }
};

/// scripts/fuzz.sh starts the LAZ and COPC fuzzers from the files these tests build: with
/// SUBSCAN_LAZ_SEEDS set, they are also written there.
void saveFuzzSeed(const std::string& name, const std::string& bytes) {
    if (const char* directory = std::getenv("SUBSCAN_LAZ_SEEDS"); directory && *directory) {
        std::ofstream(std::filesystem::path(directory) / name, std::ios::binary) << bytes;
    }
}

std::string recordsError(const std::string& file) {
    try {
        ReadContext context;
        readLasRecords(test::asBytes(file), context);
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "no error";
    return {};
}

LasRecords decodeRecords(const std::string& file) {
    ReadContext context;
    return readLasRecords(test::asBytes(file), context);
}

/// Point format 0 with two extra bytes (POINT10 + BYTE, version 2), in pointwise chunks of
/// `chunkSize`: x steps by varied amounts, z rises, the extra bytes count up and down.
struct Format0Points {
    std::vector<std::array<std::int32_t, 3>> xyz;
    std::vector<std::array<std::uint8_t, 2>> extra;

    explicit Format0Points(std::size_t count) {
        for (std::size_t i = 0; i < count; ++i) {
            const auto n = static_cast<std::int32_t>(i);
            xyz.push_back({1000 + n * 7 + (n % 3) * 2, -500, 20 + n});
            extra.push_back({static_cast<std::uint8_t>(3 * i), static_cast<std::uint8_t>(250 - i)});
        }
    }

    std::string record(std::size_t i) const {
        std::string r;
        for (std::int32_t v : xyz[i]) {
            appendBytes(r, v);
        }
        appendBytes<std::uint16_t>(r, 0);  // intensity
        r += '\x09';                       // return 1 of 1
        r.append(5, '\0');                 // class, angle, user data, point source
        r += static_cast<char>(extra[i][0]);
        r += static_cast<char>(extra[i][1]);
        return r;
    }

    /// One chunk of points [first, first + count).
    std::string chunk(std::size_t first, std::size_t count) const {
        std::string bytes = record(first);
        if (count == 1) {
            return bytes;
        }
        Encoder encoder;
        SymbolModel changedValues(64);
        IntegerCompressor dx(32, 2), dy(32, 22), dz(32, 20);
        laz::Median5 xMedian, yMedian;
        std::int32_t lastHeight = 0;  // the coder's first prediction of z
        std::array<SymbolModel, 2> byteModels{SymbolModel(256), SymbolModel(256)};
        for (std::size_t i = first + 1; i < first + count; ++i) {
            encoder.encodeSymbol(changedValues, 0);
            const std::int32_t diffX = xyz[i][0] - xyz[i - 1][0];
            dx.compress(encoder, xMedian.get(), diffX, 1);  // context: single return
            xMedian.add(diffX);
            const std::uint32_t kx = dx.lastK();
            dy.compress(encoder, yMedian.get(), 0, 1 + (kx < 20 ? kx & ~1u : 20));
            yMedian.add(0);
            const std::uint32_t k = (dx.lastK() + dy.lastK()) / 2;
            dz.compress(encoder, lastHeight, xyz[i][2], 1 + (k < 18 ? k & ~1u : 18));
            lastHeight = xyz[i][2];
            for (int b = 0; b < 2; ++b) {
                encoder.encodeSymbol(byteModels[b],
                                     static_cast<std::uint8_t>(extra[i][b] - extra[i - 1][b]));
            }
        }
        return bytes + finished(encoder);
    }
};

LazFile format0File(const Format0Points& points, std::uint32_t chunkSize) {
    LazFile file;
    file.pointFormat = 0;
    file.items = {{6, 20, 2}, {0, 2, 2}};
    file.chunkSize = chunkSize;
    file.pointCount = points.xyz.size();
    for (std::size_t first = 0; first < points.xyz.size(); first += chunkSize) {
        const std::size_t count = std::min<std::size_t>(chunkSize, points.xyz.size() - first);
        file.chunks.push_back(points.chunk(first, count));
        file.chunkPoints.push_back(static_cast<std::uint32_t>(count));
    }
    return file;
}

TEST(LazReaderTest, PointwiseFormat0WithExtraBytesInFixedChunks) {
    const Format0Points points(7);
    // Chunks of 3, 3 and 1 points: the last holds only its raw first point.
    const std::string file = format0File(points, 3).bytes();
    saveFuzzSeed("format0-extra-bytes.laz", file);
    const LasRecords records = decodeRecords(file);
    ASSERT_EQ(records.recordLength, 22u);
    ASSERT_EQ(records.size(), 7u);
    for (std::size_t i = 0; i < 7; ++i) {
        const std::string expected = points.record(i);
        EXPECT_EQ(0, std::memcmp(records.bytes.data() + 22 * i, expected.data(), 22)) << i;
    }
    const LoadedScan scan = test::decode(file, "points.laz");
    EXPECT_EQ(scan.cloud.size(), 7u);
    test::expectPosition(scan.cloud, 6, (1000 + 42) * 0.001, -0.5, 26 * 0.001);
    EXPECT_THAT(scan.formatDetail, HasSubstr("3 chunks, pointwise"));
}

TEST(LazReaderTest, MalformedPointwiseFilesAreRefused) {
    const Format0Points points(7);
    LazFile file = format0File(points, 3);

    LazFile truncatedChunk = file;
    truncatedChunk.chunks[1].resize(truncatedChunk.chunks[1].size() - 4);
    EXPECT_THAT(recordsError(truncatedChunk.bytes()), HasSubstr("chunk 2 of 3"));

    LazFile shortFirstPoint = file;
    shortFirstPoint.chunks[2].resize(10);
    EXPECT_THAT(recordsError(shortFirstPoint.bytes()), HasSubstr("fewer than its first 22-byte"));

    LazFile missingChunk = file;
    missingChunk.chunks.pop_back();
    missingChunk.chunkPoints.pop_back();
    EXPECT_THAT(recordsError(missingChunk.bytes()), HasSubstr("lists 2 chunks"));

    LazFile wrongItems = file;
    wrongItems.items = {{6, 20, 2}, {7, 2, 2}};
    EXPECT_THAT(recordsError(wrongItems.bytes()), HasSubstr("needs BYTE"));

    LazFile waves = file;
    waves.pointFormat = 4;
    waves.items = {{6, 20, 2}, {7, 8, 2}, {9, 29, 1}};
    EXPECT_THAT(recordsError(waves.bytes()), HasSubstr("wave packets"));

    std::string garbledTable = file.bytes();
    garbledTable.resize(garbledTable.size() - 6);  // the table's coded sizes lose their end
    EXPECT_THAT(recordsError(garbledTable), HasSubstr("LAZ"));
}

/// LAS 1.4 points of format 7 or 8 with `extraBytes` BYTE14 bytes, in layered chunks: x moves,
/// colour (and NIR) and the extra bytes change from point to point; the other fields stay.
struct Layered14Points {
    int format;
    std::size_t extraBytes;
    std::vector<std::int32_t> x;
    std::vector<std::array<std::uint16_t, 4>> rgbNir;
    std::vector<std::vector<std::uint8_t>> extra;

    Layered14Points(int pointFormat, std::size_t count, std::size_t extraCount)
        : format(pointFormat), extraBytes(extraCount) {
        for (std::size_t i = 0; i < count; ++i) {
            const auto n = static_cast<std::uint16_t>(i);
            x.push_back(static_cast<std::int32_t>(5000 + 11 * i - (i % 4) * 3));
            rgbNir.push_back({static_cast<std::uint16_t>(257 * (10 + n)),
                              static_cast<std::uint16_t>(300 * n + 7),
                              static_cast<std::uint16_t>(65535 - 999 * n),
                              static_cast<std::uint16_t>(1234 + 4321 * n)});
            std::vector<std::uint8_t> bytes;
            for (std::size_t b = 0; b < extraCount; ++b) {
                bytes.push_back(static_cast<std::uint8_t>(i * (b + 1) + 17 * b));
            }
            extra.push_back(bytes);
        }
    }

    std::size_t colourBytes() const { return format == 8 ? 8 : 6; }

    std::string record(std::size_t i) const {
        std::string r;
        appendBytes(r, x[i]);
        appendBytes<std::int32_t>(r, 77);    // y
        appendBytes<std::int32_t>(r, -3);    // z
        appendBytes<std::uint16_t>(r, 500);  // intensity
        r += '\x11';                         // return 1 of 1
        r += '\x00';                         // flags, channel 0
        r += '\x02';                         // ground
        r += '\x00';                         // user data
        appendBytes<std::int16_t>(r, 0);     // scan angle
        appendBytes<std::uint16_t>(r, 9);    // point source
        appendBytes(r, 12.5);                // GPS time
        for (std::size_t c = 0; c < colourBytes() / 2; ++c) {
            appendBytes(r, rgbNir[i][c]);
        }
        for (std::uint8_t b : extra[i]) {
            r += static_cast<char>(b);
        }
        return r;
    }

    std::string chunk(std::size_t first, std::size_t count) const {
        std::string chunk = record(first);
        Encoder xy, rgb, nir;
        std::vector<Encoder> bytes(extraBytes);
        SymbolModel changedValues(128);
        IntegerCompressor dx(32, 2), dy(32, 22);
        laz::Median5 xMedian, yMedian;
        laz::RgbModels rgbModels;
        SymbolModel nirChanged(4);
        std::array<SymbolModel, 2> nirDifferences{SymbolModel(256), SymbolModel(256)};
        std::vector<SymbolModel> byteModels(extraBytes, SymbolModel(256));
        for (std::size_t i = first + 1; i < first + count; ++i) {
            // Last point: return 1 of 1 (first and last), time unchanged: context 3.
            xy.encodeSymbol(changedValues, 0);
            const std::int32_t diff = x[i] - x[i - 1];
            // The median index of m = 0 (1 of 1), time unchanged, is 0; context: single return.
            dx.compress(xy, xMedian.get(), diff, 1);
            xMedian.add(diff);
            const std::uint32_t k = dx.lastK();
            dy.compress(xy, yMedian.get(), 0, 1 + (k < 20 ? k & ~1u : 20));
            yMedian.add(0);
            encodeRgb(rgb, rgbModels, rgbNir[i - 1], rgbNir[i]);
            if (format == 8) {
                const std::uint16_t last = rgbNir[i - 1][3];
                const std::uint16_t now = rgbNir[i][3];
                const std::uint32_t changed = ((last & 0xFF) != (now & 0xFF) ? 1u : 0u) |
                                              ((last >> 8) != (now >> 8) ? 2u : 0u);
                nir.encodeSymbol(nirChanged, changed);
                if (changed & 1) {
                    nir.encodeSymbol(nirDifferences[0], static_cast<std::uint8_t>(now - last));
                }
                if (changed & 2) {
                    nir.encodeSymbol(nirDifferences[1],
                                     static_cast<std::uint8_t>((now >> 8) - (last >> 8)));
                }
            }
            for (std::size_t b = 0; b < extraBytes; ++b) {
                bytes[b].encodeSymbol(byteModels[b],
                                      static_cast<std::uint8_t>(extra[i][b] - extra[i - 1][b]));
            }
        }
        // Layers: 9 of POINT14 (only the first, coordinates and returns, changes), the colour
        // layer(s), one per extra byte. A one-point chunk has no layers at all.
        std::vector<std::string> layers(9);
        if (count > 1) {
            layers[0] = finished(xy);
            layers.push_back(finished(rgb));
            if (format == 8) {
                layers.push_back(finished(nir));
            }
            for (Encoder& encoder : bytes) {
                layers.push_back(finished(encoder));
            }
        } else {
            layers.resize(9 + (format == 8 ? 2 : 1) + extraBytes);
        }
        appendBytes<std::uint32_t>(chunk, static_cast<std::uint32_t>(count));
        for (const std::string& layer : layers) {
            appendBytes<std::uint32_t>(chunk, static_cast<std::uint32_t>(layer.size()));
        }
        for (const std::string& layer : layers) {
            chunk += layer;
        }
        return chunk;
    }

    /// The colour coder's input side: which bytes changed, and each byte's difference to what
    /// the decoder predicts (red from its last value, green and blue from red's change).
    static void encodeRgb(Encoder& encoder, laz::RgbModels& models,
                          const std::array<std::uint16_t, 4>& last,
                          const std::array<std::uint16_t, 4>& now) {
        const auto low = [](std::uint16_t v) { return static_cast<std::int32_t>(v & 0xFF); };
        const auto high = [](std::uint16_t v) { return static_cast<std::int32_t>(v >> 8); };
        std::uint32_t changed = 0;
        for (int c = 0; c < 3; ++c) {
            changed |= (low(last[c]) != low(now[c]) ? 1u : 0u) << (2 * c);
            changed |= (high(last[c]) != high(now[c]) ? 1u : 0u) << (2 * c + 1);
        }
        changed |= (now[0] != now[1] || now[0] != now[2]) ? 64u : 0u;
        encoder.encodeSymbol(models.changedBytes, changed);
        const auto put = [&](int bit, std::int32_t value, std::int32_t prediction) {
            if (changed & (1u << bit)) {
                encoder.encodeSymbol(models.differences[bit],
                                     static_cast<std::uint8_t>(value - prediction));
            }
        };
        put(0, low(now[0]), low(last[0]));
        put(1, high(now[0]), high(last[0]));
        ASSERT_TRUE(changed & 64) << "the test's colours are never grey";
        std::int32_t diff = low(now[0]) - low(last[0]);
        put(2, low(now[1]), laz::clampByte(diff + low(last[1])));
        diff = (diff + low(now[1]) - low(last[1])) / 2;
        put(4, low(now[2]), laz::clampByte(diff + low(last[2])));
        diff = high(now[0]) - high(last[0]);
        put(3, high(now[1]), laz::clampByte(diff + high(last[1])));
        diff = (diff + high(now[1]) - high(last[1])) / 2;
        put(5, high(now[2]), laz::clampByte(diff + high(last[2])));
    }
};

LazFile layeredFile(const Layered14Points& points, const std::vector<std::size_t>& chunkPoints) {
    LazFile file;
    file.pointFormat = points.format;
    file.minorVersion = 4;
    file.compressor = 3;
    file.chunkSize = 0xFFFFFFFFu;
    file.items = {{10, 30, 3}};
    file.items.push_back(points.format == 8 ? Item{12, 8, 3} : Item{11, 6, 3});
    if (points.extraBytes > 0) {
        file.items.push_back({14, static_cast<std::uint16_t>(points.extraBytes), 3});
    }
    std::size_t first = 0;
    for (std::size_t count : chunkPoints) {
        file.chunks.push_back(points.chunk(first, count));
        file.chunkPoints.push_back(static_cast<std::uint32_t>(count));
        first += count;
    }
    file.pointCount = first;
    return file;
}

TEST(LazReaderTest, LayeredFormats7And8WithExtraBytesInVariableChunks) {
    for (const int format : {7, 8}) {
        SCOPED_TRACE(format);
        const Layered14Points points(format, 40, 3);
        // Variable chunks, one of them a single point (no layers at all).
        const std::string file = layeredFile(points, {25, 1, 14}).bytes();
        saveFuzzSeed(fmt::format("format{}-extra-bytes.laz", format), file);
        const LasRecords records = decodeRecords(file);
        ASSERT_EQ(records.pointFormat, format);
        ASSERT_EQ(records.recordLength, 30 + points.colourBytes() + 3);
        ASSERT_EQ(records.size(), 40u);
        for (std::size_t i = 0; i < 40; ++i) {
            const std::string expected = points.record(i);
            EXPECT_EQ(0, std::memcmp(records.bytes.data() + records.recordLength * i,
                                     expected.data(), expected.size()))
                << "point " << i;
        }
        const LoadedScan scan = test::decode(file, "points.laz");
        ASSERT_TRUE(scan.cloud.hasColors());
        // Colour 39: red 257 * 49 is the 8-bit 49 stored in 16 bits.
        EXPECT_EQ(scan.cloud.colors[39].r, 49);
        EXPECT_EQ(scan.cloud.classifications, std::vector<std::uint8_t>(40, 2));  // ground
        EXPECT_THAT(scan.formatDetail, HasSubstr("layered"));
    }
}

TEST(LazReaderTest, MalformedLayeredChunksAreRefused) {
    const Layered14Points points(8, 10, 1);
    const LazFile file = layeredFile(points, {6, 4});

    const std::size_t countAt = points.record(0).size();  // right after the raw first point
    LazFile wrongCount = file;
    std::memcpy(wrongCount.chunks[1].data() + countAt, "\x05\x00\x00\x00", 4);
    EXPECT_THAT(recordsError(wrongCount.bytes()), HasSubstr("says it holds 5 points"));

    LazFile longLayer = file;
    std::memcpy(longLayer.chunks[0].data() + countAt + 4, "\xFF\xFF\x00\x00", 4);
    EXPECT_THAT(recordsError(longLayer.bytes()), HasSubstr("beyond the end of the chunk"));

    LazFile version4 = file;
    version4.items[1].version = 4;
    EXPECT_THAT(recordsError(version4.bytes()), HasSubstr("version 4 is not"));

    LazFile pointwiseItems = file;
    pointwiseItems.compressor = 2;
    EXPECT_THAT(recordsError(pointwiseItems.bytes()), HasSubstr("must match the compressor"));
}

/// A COPC file of `points` (format 6-8) in two nodes: the root (key 0-0-0-0) and one child
/// (1-0-0-0) listed on a second hierarchy page that the root page points to.
struct CopcLayout {
    std::string bytes;
    std::size_t infoPayload = 0;  // offset of the copc info VLR's payload
    std::size_t rootPage = 0;
    std::size_t childPage = 0;
};

CopcLayout copcFile(const Layered14Points& points, std::size_t rootPoints) {
    LazFile file = layeredFile(points, {rootPoints, points.x.size() - rootPoints});
    file.copcInfoVlr = true;
    CopcLayout copc;
    copc.bytes = file.bytes();
    copc.infoPayload = 375 + 54;
    const auto pointData = loadLittleEndian<std::uint32_t>(copc.bytes.data() + 96);
    const std::uint64_t firstChunk = pointData + 8;
    const auto entry = [](std::string& page, std::array<std::int32_t, 4> key, std::uint64_t offset,
                          std::int32_t byteSize, std::int32_t pointCount) {
        for (std::int32_t k : key) {
            appendBytes(page, k);
        }
        appendBytes(page, offset);
        appendBytes(page, byteSize);
        appendBytes(page, pointCount);
    };
    // The hierarchy EVLR's 60-byte header (not read: the info VLR points at the page itself).
    copc.bytes += std::string(60, '\0');
    copc.rootPage = copc.bytes.size();
    copc.childPage = copc.rootPage + 64;
    std::string pages;
    entry(pages, {0, 0, 0, 0}, firstChunk, static_cast<std::int32_t>(file.chunks[0].size()),
          static_cast<std::int32_t>(rootPoints));
    entry(pages, {1, 0, 0, 0}, copc.childPage, 32, -1);
    entry(pages, {1, 0, 0, 0}, firstChunk + file.chunks[0].size(),
          static_cast<std::int32_t>(file.chunks[1].size()),
          static_cast<std::int32_t>(points.x.size() - rootPoints));
    copc.bytes += pages;
    const auto put = [&](std::size_t offset, auto value) {
        std::memcpy(copc.bytes.data() + offset, &value, sizeof(value));
    };
    put(copc.infoPayload + 24, 100.0);  // half size
    put(copc.infoPayload + 32, 0.5);    // root spacing
    put(copc.infoPayload + 40, static_cast<std::uint64_t>(copc.rootPage));
    put(copc.infoPayload + 48, std::uint64_t{64});
    return copc;
}

TEST(LazReaderTest, CopcNodesAreReadThroughTheHierarchyPages) {
    const Layered14Points points(7, 30, 0);
    const CopcLayout copc = copcFile(points, 18);
    saveFuzzSeed("two-nodes.copc.laz", copc.bytes);
    const LasRecords records = decodeRecords(copc.bytes);
    ASSERT_EQ(records.size(), 30u);
    for (std::size_t i = 0; i < 30; ++i) {
        const std::string expected = points.record(i);
        EXPECT_EQ(0, std::memcmp(records.bytes.data() + records.recordLength * i, expected.data(),
                                 expected.size()))
            << "point " << i;
    }
    const LoadedScan scan = test::decode(copc.bytes, "x.copc.laz");
    // The root's 18 points at level 0, the other node's 12 at level 1.
    EXPECT_THAT(scan.formatDetail, HasSubstr("octree of 2 levels, 2 nodes, root spacing 0.5; "
                                             "points per level 18, 12"));
    // Every record says ground (class 2, byte 16 of POINT14): so must the cloud of both nodes.
    EXPECT_EQ(scan.cloud.classifications, std::vector<std::uint8_t>(30, 2));
}

TEST(LazReaderTest, MalformedCopcHierarchiesAreRefused) {
    const Layered14Points points(7, 20, 0);
    const CopcLayout copc = copcFile(points, 12);
    const auto with = [&](std::size_t offset, auto value) {
        std::string bytes = copc.bytes;
        std::memcpy(bytes.data() + offset, &value, sizeof(value));
        return bytes;
    };
    // The child page's entry (the one with the points) sits at the child page.
    EXPECT_THAT(recordsError(with(copc.rootPage + 32 + 16, std::uint64_t{1} << 40)),
                HasSubstr("hierarchy page at byte 1099511627776"));
    EXPECT_THAT(recordsError(with(copc.childPage + 24, std::int32_t{1} << 30)),
                HasSubstr("node 1-0-0-0 lies beyond the end of the file"));
    EXPECT_THAT(recordsError(with(copc.childPage + 28, std::int32_t{-5})),
                HasSubstr("point count -5"));
    EXPECT_THAT(recordsError(with(copc.childPage + 28, std::int32_t{9})),
                HasSubstr("nodes hold 21 points, but the LAS header declares 20"));
    EXPECT_THAT(recordsError(with(copc.infoPayload + 48, std::uint64_t{40})),
                HasSubstr("multiple of its 32-byte entries"));
    // A child page that lists the root page again is read once, not forever.
    const std::string cycle =
        with(copc.rootPage + 32 + 16, static_cast<std::uint64_t>(copc.rootPage));
    EXPECT_THAT(recordsError(cycle), HasSubstr("nodes hold 12 points"));
}

}  // namespace
}  // namespace subscan
