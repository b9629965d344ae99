// The LAZ encoder (io/laz/LazEncoder.h) through the project's own decoder: random LAS 1.4
// records of formats 6, 7 and 8 (test::randomLas14Records runs every coder path) decode to
// exactly the bytes encoded, in chunks of any size; the layers of fields that do not change stay
// empty; bad input is an error. LazEncoderDataTest checks the bytes against files that LASzip
// and laz-perf wrote.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/ArithmeticDecoder.h"
#include "io/laz/ArithmeticEncoder.h"
#include "io/laz/IntegerCompressor.h"
#include "io/laz/IntegerDecompressor.h"
#include "io/laz/LazDecoder.h"
#include "io/laz/LazEncoder.h"
#include "support/Las14Records.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

/// Decodes `chunk` and expects exactly `records` back, naming the first differing point.
void expectChunkDecodesTo(const std::vector<std::byte>& chunk, std::span<const std::byte> records,
                          const laz::LazLayout& layout) {
    const std::size_t count = records.size() / layout.recordLength;
    std::vector<std::byte> decoded(records.size());
    laz::decodeChunk(chunk, count, layout, decoded.data());
    const auto [expected, actual] = std::ranges::mismatch(records, decoded);
    if (expected != records.end()) {
        const std::size_t at = static_cast<std::size_t>(expected - records.begin());
        ADD_FAILURE() << "point " << at / layout.recordLength << " of " << count
                      << " differs at byte " << at % layout.recordLength;
    }
}

/// The byte counts of a chunk's layers (after its raw first point and point count).
std::vector<std::uint32_t> layerSizes(const std::vector<std::byte>& chunk,
                                      const laz::LazLayout& layout, std::size_t layers) {
    std::vector<std::uint32_t> sizes;
    for (std::size_t i = 0; i < layers; ++i) {
        sizes.push_back(
            loadLittleEndian<std::uint32_t>(chunk.data() + layout.recordLength + 4 + 4 * i));
    }
    return sizes;
}

TEST(LazEncoderTest, AnEmptyStreamEndsInLaszipsFourBytes) {
    // FastAC's end with the initial interval: one byte (base + 2^24 >> 24) pins a value inside
    // it, then three zeros of padding; LASzip and laz-perf write these for a one-point chunk.
    laz::ArithmeticEncoder encoder;
    const std::vector<std::byte> expected{std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0}};
    EXPECT_EQ(encoder.finish(), expected);
    // The encoder starts over after finishing.
    EXPECT_EQ(encoder.finish(), expected);
}

TEST(LazEncoderTest, IntegersAtTheEdgesOfTheirRangesRoundTrip) {
    constexpr std::int32_t kMin = std::numeric_limits<std::int32_t>::min();
    constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max();
    // (prediction, value) pairs whose correctors are 0, 1, -1, the largest k, and wrap around.
    const std::vector<std::pair<std::int32_t, std::int32_t>> wide{
        {0, 0},       {0, 1},     {1, 0},     {0, kMin}, {kMin, 0}, {0, kMax},    {kMax, kMin},
        {kMin, kMax}, {-1, kMax}, {kMax, -1}, {7, 263},  {263, 7},  {0, 1 << 30}, {5, -(1 << 20)}};
    const std::vector<std::pair<std::int32_t, std::int32_t>> narrow{
        {0, 65535}, {65535, 0}, {-32768, 32767}, {32767, -32768}, {0, 32768}, {100, 100}, {0, 1}};
    laz::ArithmeticEncoder encoder;
    laz::IntegerCompressor wideOut(32, 2);
    laz::IntegerCompressor narrowOut(16, 1);
    std::vector<std::uint32_t> ks;
    for (const auto& [prediction, value] : wide) {
        wideOut.compress(encoder, prediction, value, 1);
        ks.push_back(wideOut.lastK());
    }
    for (const auto& [prediction, value] : narrow) {
        narrowOut.compress(encoder, prediction, value);
        ks.push_back(narrowOut.lastK());
    }
    const std::vector<std::byte> bytes = encoder.finish();

    laz::ArithmeticDecoder decoder(bytes);
    laz::IntegerDecompressor wideIn(32, 2);
    laz::IntegerDecompressor narrowIn(16, 1);
    std::size_t i = 0;
    for (const auto& [prediction, value] : wide) {
        EXPECT_EQ(wideIn.decompress(decoder, prediction, 1), value) << prediction;
        EXPECT_EQ(wideIn.lastK(), ks[i++]);
    }
    for (const auto& [prediction, value] : narrow) {
        // 16-bit values come back in [0, 65536): what the item coders cast to their types.
        EXPECT_EQ(static_cast<std::uint16_t>(narrowIn.decompress(decoder, prediction)),
                  static_cast<std::uint16_t>(value))
            << prediction;
        EXPECT_EQ(narrowIn.lastK(), ks[i++]);
    }
    // The range's minimum is the only corrector of 32 bits; 0 and 1 have none.
    EXPECT_EQ(ks[3], 32u);
    EXPECT_EQ(ks[0], 0u);
    EXPECT_EQ(ks[1], 0u);
}

class LazEncoderFormatTest : public ::testing::TestWithParam<test::Las14Format> {};

TEST_P(LazEncoderFormatTest, RandomRecordsDecodeToTheSameBytesInChunksOfAnySize) {
    const auto [format, extra] = GetParam();
    const laz::LazLayout layout =
        laz::layeredLazLayout(format, test::las14RecordLength(format, extra));
    const std::vector<std::byte> records = test::randomLas14Records(
        {format, extra, true, static_cast<std::uint32_t>(format * 100 + extra)}, 6000);
    laz::ChunkEncoder encoder(layout);  // one encoder for all chunks: models reset per chunk
    std::size_t first = 0;
    for (const std::size_t count : {1, 2, 3, 1, 57, 1000, 4936}) {
        SCOPED_TRACE(fmt::format("chunk of {} points from point {}", count, first));
        const std::span<const std::byte> chunkRecords =
            std::span(records).subspan(first * layout.recordLength, count * layout.recordLength);
        const std::vector<std::byte> chunk = encoder.encode(chunkRecords);
        // The first point is stored as it is.
        EXPECT_TRUE(std::equal(chunkRecords.begin(), chunkRecords.begin() + layout.recordLength,
                               chunk.begin()));
        EXPECT_EQ(loadLittleEndian<std::uint32_t>(chunk.data() + layout.recordLength), count);
        expectChunkDecodesTo(chunk, chunkRecords, layout);
        first += count;
    }
    EXPECT_EQ(first, 6000u);
}

INSTANTIATE_TEST_SUITE_P(Formats, LazEncoderFormatTest,
                         ::testing::Values(test::Las14Format{6, 0}, test::Las14Format{6, 3},
                                           test::Las14Format{7, 0}, test::Las14Format{7, 1},
                                           test::Las14Format{8, 0}, test::Las14Format{8, 5}),
                         [](const ::testing::TestParamInfo<test::Las14Format>& format) {
                             return test::las14FormatName(format.param);
                         });

void storeColour(std::byte* p, const std::array<std::uint16_t, 4>& rgbNir) {
    for (std::size_t i = 0; i < 4; ++i) {
        storeLittleEndian(p + 2 * i, rgbNir[i]);
    }
}

/// Records of format 8 with two extra bytes, all alike but for the fields `vary` changes.
std::vector<std::byte> format8Points(std::size_t count,
                                     const std::function<void(std::size_t, std::byte*)>& vary) {
    const std::size_t length = test::las14RecordLength(8, 2);
    std::vector<std::byte> records(count * length);
    for (std::size_t i = 0; i < count; ++i) {
        std::byte* p = records.data() + i * length;
        storeLittleEndian(p, static_cast<std::int32_t>(1000 + 13 * i));    // x
        storeLittleEndian(p + 4, static_cast<std::int32_t>(-50 + 3 * i));  // y
        storeLittleEndian(p + 8, static_cast<std::int32_t>(7 * (i % 5)));  // z
        storeLittleEndian(p + 12, std::uint16_t{900});                     // intensity
        p[14] = std::byte{0x11};                                           // return 1 of 1
        storeLittleEndian(p + 22, 12.5);                                   // GPS time
        storeColour(p + 30, {77, 77, 77, 3});                              // grey, NIR 3
        vary(i, p);
    }
    return records;
}

TEST(LazEncoderTest, LayersOfUnchangedFieldsStayEmpty) {
    const laz::LazLayout layout = laz::layeredLazLayout(8, test::las14RecordLength(8, 2));
    laz::ChunkEncoder encoder(layout);
    // 9 layers of POINT14, RGB and NIR, two extra bytes.
    constexpr std::size_t kLayers = 13;

    const std::vector<std::byte> still = format8Points(50, [](std::size_t, std::byte*) {});
    const std::vector<std::byte> stillChunk = encoder.encode(still);
    std::vector<std::uint32_t> sizes = layerSizes(stillChunk, layout, kLayers);
    // Coordinates and returns, and z, are always written (as LASzip does); nothing else changed.
    EXPECT_GT(sizes[0], 4u);
    EXPECT_GT(sizes[1], 4u);
    EXPECT_EQ(std::vector<std::uint32_t>(sizes.begin() + 2, sizes.end()),
              std::vector<std::uint32_t>(kLayers - 2, 0));
    expectChunkDecodesTo(stillChunk, still, layout);

    // One field at a time: its layer only.
    const std::vector<std::pair<std::size_t, std::function<void(std::size_t, std::byte*)>>>
        oneField{
            {2, [](std::size_t i, std::byte* p) { p[16] = static_cast<std::byte>(i % 3); }},
            {3,
             [](std::size_t i, std::byte* p) { p[15] = static_cast<std::byte>(i % 2 ? 0x41 : 0); }},
            {4, [](std::size_t i,
                   std::byte* p) { storeLittleEndian(p + 12, static_cast<std::uint16_t>(i)); }},
            {5, [](std::size_t i,
                   std::byte* p) { storeLittleEndian(p + 18, static_cast<std::int16_t>(-i)); }},
            {6, [](std::size_t i, std::byte* p) { p[17] = static_cast<std::byte>(i / 10); }},
            {7, [](std::size_t i,
                   std::byte* p) { storeLittleEndian(p + 20, static_cast<std::uint16_t>(i / 7)); }},
            {8, [](std::size_t i, std::byte* p) { storeLittleEndian(p + 22, 12.5 + 0.001 * i); }},
            {9,
             [](std::size_t i, std::byte* p) {
                 storeLittleEndian(p + 32, static_cast<std::uint16_t>(77 + i));
             }},
            {10,
             [](std::size_t i, std::byte* p) {
                 storeLittleEndian(p + 36, static_cast<std::uint16_t>(3 + 300 * i));
             }},
            {12, [](std::size_t i, std::byte* p) { p[39] = static_cast<std::byte>(i * i); }},
        };
    for (const auto& [layer, vary] : oneField) {
        SCOPED_TRACE(fmt::format("layer {}", layer));
        const std::vector<std::byte> records = format8Points(50, vary);
        const std::vector<std::byte> chunk = encoder.encode(records);
        sizes = layerSizes(chunk, layout, kLayers);
        for (std::size_t i = 2; i < kLayers; ++i) {
            EXPECT_EQ(sizes[i] > 0, i == layer) << "layer " << i << " has " << sizes[i] << " bytes";
        }
        expectChunkDecodesTo(chunk, records, layout);
    }

    // A constant colour that is not grey writes the colour layer all the same: LASzip marks the
    // layer changed by its change mask, whose grey bit is set.
    const std::vector<std::byte> colour = format8Points(20, [](std::size_t, std::byte* p) {
        storeColour(p + 30, {10, 20, 30, 3});
    });
    const std::vector<std::byte> colourChunk = encoder.encode(colour);
    EXPECT_GT(layerSizes(colourChunk, layout, kLayers)[9], 0u);
    expectChunkDecodesTo(colourChunk, colour, layout);
}

TEST(LazEncoderTest, AOnePointChunkIsThePointAndEmptyStreams) {
    const laz::LazLayout layout = laz::layeredLazLayout(7, test::las14RecordLength(7, 1));
    const std::vector<std::byte> record = test::randomLas14Records({7, 1, true, 5}, 1);
    const std::vector<std::byte> chunk = laz::ChunkEncoder(layout).encode(record);
    // The record, the count 1, 11 layer sizes: 4 and 4 (the two layers always written, holding
    // only an empty stream's end), then zeros; then the two 4-byte streams.
    std::vector<std::byte> expected = record;
    const std::vector<std::uint32_t> header{1, 4, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    for (const std::uint32_t value : header) {
        const std::size_t at = expected.size();
        expected.resize(at + 4);
        storeLittleEndian(expected.data() + at, value);
    }
    for (int stream = 0; stream < 2; ++stream) {
        expected.insert(expected.end(), {std::byte{1}, std::byte{0}, std::byte{0}, std::byte{0}});
    }
    EXPECT_EQ(chunk, expected);
    expectChunkDecodesTo(chunk, record, layout);
}

TEST(LazEncoderTest, ScannerChannelsSwitchAwayAndBack) {
    const std::size_t length = test::las14RecordLength(7, 2);
    const laz::LazLayout layout = laz::layeredLazLayout(7, length);
    // A chunk that starts on channel 3, visits every channel, returns to channels seen before
    // (where RGB and the extra bytes predict from the channel they left, as LASzip does).
    const std::vector<int> channels{3, 3, 1, 1, 0, 3, 2, 2, 0, 1, 3, 3, 0, 0, 2, 1};
    std::vector<std::byte> records =
        test::randomLas14Records({7, 2, false, 9}, channels.size() * 20);
    for (std::size_t i = 0; i < records.size() / length; ++i) {
        std::byte& flags = records[i * length + 15];
        flags = (flags & std::byte{0xCF}) | static_cast<std::byte>(channels[i / 20] << 4);
    }
    laz::ChunkEncoder encoder(layout);
    expectChunkDecodesTo(encoder.encode(records), records, layout);
    // Each point its own channel change.
    for (std::size_t i = 0; i < records.size() / length; ++i) {
        std::byte& flags = records[i * length + 15];
        flags =
            (flags & std::byte{0xCF}) | static_cast<std::byte>(channels[i % channels.size()] << 4);
    }
    expectChunkDecodesTo(encoder.encode(records), records, layout);
}

/// The bytes of layer `layer` of a chunk with `layers` layers.
std::vector<std::byte> layerBytes(const std::vector<std::byte>& chunk, const laz::LazLayout& layout,
                                  std::size_t layers, std::size_t layer) {
    const std::vector<std::uint32_t> sizes = layerSizes(chunk, layout, layers);
    std::size_t at = layout.recordLength + 4 + 4 * layers;
    for (std::size_t i = 0; i < layer; ++i) {
        at += sizes[i];
    }
    return {chunk.begin() + static_cast<std::ptrdiff_t>(at),
            chunk.begin() + static_cast<std::ptrdiff_t>(at + sizes[layer])};
}

TEST(LazEncoderTest, OtherItemsFollowTheChannelOnlyWhereItChanges) {
    // LASzip codes RGB, NIR and extra bytes in the scanner channel's context only at the points
    // where the channel changes, in context 0 elsewhere. So 30 points of channel 0, then 30 of
    // channel 1, code their colours and extra bytes as 30 of channel 0, one of channel 1 and 29
    // of channel 0 do: context 0, 1 at point 30, 0 again.
    const std::size_t length = test::las14RecordLength(7, 1);
    const laz::LazLayout layout = laz::layeredLazLayout(7, length);
    constexpr std::size_t kLayers = 9 + 1 + 1;
    std::vector<std::byte> stay = test::randomLas14Records({7, 1, false, 31}, 60);
    for (std::size_t i = 0; i < 60; ++i) {
        std::byte* p = stay.data() + i * length;
        for (std::size_t c = 0; c < 3; ++c) {
            storeLittleEndian(p + 30 + 2 * c, static_cast<std::uint16_t>((c + 1) * 7919 * i));
        }
        p[36] = static_cast<std::byte>(13 * i);  // the extra byte
    }
    std::vector<std::byte> back = stay;
    for (std::size_t i = 30; i < 60; ++i) {
        std::byte& flags = stay[i * length + 15];
        flags = (flags & std::byte{0xCF}) | std::byte{0x10};
    }
    back[30 * length + 15] = (back[30 * length + 15] & std::byte{0xCF}) | std::byte{0x10};
    laz::ChunkEncoder encoder(layout);
    const std::vector<std::byte> stayChunk = encoder.encode(stay);
    const std::vector<std::byte> backChunk = encoder.encode(back);
    for (const std::size_t layer : {kLayers - 2, kLayers - 1}) {
        SCOPED_TRACE(fmt::format("layer {}", layer));
        const std::vector<std::byte> colours = layerBytes(stayChunk, layout, kLayers, layer);
        EXPECT_FALSE(colours.empty());
        EXPECT_EQ(colours, layerBytes(backChunk, layout, kLayers, layer));
    }
    expectChunkDecodesTo(stayChunk, stay, layout);
    expectChunkDecodesTo(backChunk, back, layout);
}

TEST(LazEncoderTest, GpsTimeSequencesRoundTrip) {
    const std::size_t length = test::las14RecordLength(6, 0);
    const laz::LazLayout layout = laz::layeredLazLayout(6, length);
    // Regular pulses, multiples of the step (up to and beyond 500, backwards to beyond -10),
    // far-below-step differences, five interleaved flight lines (one more than the coder's four
    // sequences), returns to earlier lines, and the odd doubles: -0.0 after 0.0, NaN after NaN,
    // infinity, the largest double. Many rounds: a context mixed up shows only once the models
    // of the contexts have adapted apart.
    std::vector<double> times;
    // Within one binade (2^20 to 2^21), where the same step is the same bit difference: 10 us,
    // some 43,000 steps of 2^-32, so that even 700 steps fit the coder's 32-bit differences.
    constexpr double kStep = 1e-5;
    double t = 1.5e6;
    for (int round = 0; round < 30; ++round) {
        for (int i = 0; i < 20; ++i) {
            times.push_back(t += kStep);
        }
        for (const double multiple : {2.0, 9.0, 10.0, 499.0, 500.0, 700.0, 1.0, -1.0, -9.0, -10.0,
                                      -40.0, 0.001, 0.001, 0.001, 0.001, 0.001, 1.0, 3.0}) {
            // Exact small multiples, noisy large ones (a few thousand bit steps of 2^-32): the
            // contexts of the two learn different correctors.
            const double noise = multiple >= 10.0 ? 0x1p-32 * (round * 977 % 4093) : 0.0;
            times.push_back(t += kStep * multiple + noise);
        }
        for (int i = 0; i < 20; ++i) {
            times.push_back(1000.0 + 3600.0 * (i % 5) + 0.01 * (i + 20 * round));
        }
        for (const double odd : {0.0, -0.0, 0.0, std::nan(""), std::nan(""), -std::nan(""),
                                 std::numeric_limits<double>::infinity(),
                                 std::numeric_limits<double>::max(), 1000.0, -1000.0}) {
            times.push_back(odd);
        }
    }
    std::vector<std::byte> records(times.size() * length, std::byte{0});
    for (std::size_t i = 0; i < times.size(); ++i) {
        std::byte* p = records.data() + i * length;
        storeLittleEndian(p, static_cast<std::int32_t>(i));
        p[14] = std::byte{0x11};
        storeLittleEndian(p + 22, times[i]);
    }
    laz::ChunkEncoder encoder(layout);
    expectChunkDecodesTo(encoder.encode(records), records, layout);
}

TEST(LazEncoderTest, LaszipRecordReadsBackAsItsLayout) {
    for (const int format : {6, 7, 8}) {
        for (const std::size_t extra : {0, 1, 7}) {
            SCOPED_TRACE(fmt::format("format {}, {} extra bytes", format, extra));
            const std::size_t length = test::las14RecordLength(format, extra);
            const laz::LazLayout layout = laz::layeredLazLayout(format, length);
            EXPECT_EQ(layout.recordLength, length);
            EXPECT_EQ(layout.items.size(), (format == 6 ? 1u : 2u) + (extra > 0 ? 1u : 0u));
            const std::vector<std::byte> payload = laz::laszipRecordPayload(layout);
            EXPECT_EQ(payload.size(), 34 + 6 * layout.items.size());
            const laz::LazLayout parsed = laz::parseLaszipRecord(payload, format, length);
            EXPECT_EQ(parsed.compressor, laz::kCompressorLayeredChunked);
            EXPECT_EQ(parsed.chunkSize, laz::kVariableChunkSize);
            EXPECT_EQ(parsed.recordLength, length);
            ASSERT_EQ(parsed.items.size(), layout.items.size());
            for (std::size_t i = 0; i < parsed.items.size(); ++i) {
                EXPECT_EQ(parsed.items[i].type, layout.items[i].type);
                EXPECT_EQ(parsed.items[i].size, layout.items[i].size);
                EXPECT_EQ(parsed.items[i].version, 3);
            }
        }
    }
}

TEST(LazEncoderTest, BadInputIsAClearError) {
    EXPECT_THAT(test::errorMessage([] { laz::layeredLazLayout(3, 34); }),
                HasSubstr("point formats 6, 7 and 8, not point format 3"));
    EXPECT_THAT(test::errorMessage([] { laz::layeredLazLayout(9, 59); }),
                HasSubstr("not point format 9"));
    EXPECT_THAT(test::errorMessage([] { laz::layeredLazLayout(7, 35); }),
                HasSubstr("at least 36 bytes, not 35"));

    const laz::LazLayout layout = laz::layeredLazLayout(6, 30);
    laz::ChunkEncoder encoder(layout);
    EXPECT_THAT(test::errorMessage([&] { encoder.encode({}); }), HasSubstr("at least one point"));
    const std::vector<std::byte> partial(45);
    EXPECT_THAT(test::errorMessage([&] { encoder.encode(partial); }),
                HasSubstr("45 bytes of point records are not a whole number of 30-byte records"));
    // The encoder still works after refusing.
    const std::vector<std::byte> records = test::randomLas14Records({6, 0, true, 3}, 10);
    expectChunkDecodesTo(encoder.encode(records), records, layout);

    laz::LazLayout pointwise = layout;
    pointwise.compressor = laz::kCompressorPointwiseChunked;
    EXPECT_THAT(test::errorMessage([&] { laz::ChunkEncoder{pointwise}; }),
                HasSubstr("not compressor 2"));
    EXPECT_THAT(test::errorMessage([] {
                    laz::makeLayeredItemEncoder({laz::ItemType::Point10, 20, 2});
                }),
                HasSubstr("not item type 6"));

    laz::Chunk tooLarge;
    tooLarge.pointCount = std::uint64_t{1} << 32;
    tooLarge.byteSize = 10;
    EXPECT_THAT(test::errorMessage([&] { laz::encodeChunkTable(std::span(&tooLarge, 1), true); }),
                HasSubstr("4294967296 points"));
}

}  // namespace
}  // namespace subscan
