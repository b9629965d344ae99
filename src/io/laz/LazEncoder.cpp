#include "io/laz/LazEncoder.h"

#include <limits>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/WriterSupport.h"
#include "io/laz/ArithmeticEncoder.h"
#include "io/laz/IntegerCompressor.h"

namespace subscan::laz {

namespace {

// What the laszip VLR says wrote the file (LASzip 3.4 r3), and its coder: 0, arithmetic.
constexpr std::uint8_t kLaszipVersionMajor = 3;
constexpr std::uint8_t kLaszipVersionMinor = 4;
constexpr std::uint16_t kLaszipRevision = 3;
constexpr std::uint16_t kArithmeticCoder = 0;
constexpr std::size_t kChunkCountSize = 4;
constexpr std::size_t kLayerSizeSize = 4;

std::uint32_t checkedUint32(std::uint64_t value, const char* what) {
    if (value > std::numeric_limits<std::uint32_t>::max()) {
        throw Error(fmt::format("a LAZ chunk cannot hold {} {} (at most 2^32 - 1)", value, what));
    }
    return static_cast<std::uint32_t>(value);
}

}  // namespace

LazLayout layeredLazLayout(int pointFormat, std::size_t recordLength) {
    if (pointFormat < 6 || pointFormat > 8) {
        throw Error(fmt::format(
            "the LAZ encoder writes LAS 1.4 point formats 6, 7 and 8, not point format {}",
            pointFormat));
    }
    LazLayout layout;
    layout.compressor = kCompressorLayeredChunked;
    layout.chunkSize = kVariableChunkSize;
    layout.items = pointFormatItems(pointFormat);
    for (const ItemSpec& item : layout.items) {
        layout.recordLength += item.size;
    }
    if (recordLength < layout.recordLength) {
        throw Error(fmt::format("point format {} records have at least {} bytes, not {}",
                                pointFormat, layout.recordLength, recordLength));
    }
    const std::size_t extraBytes = recordLength - layout.recordLength;
    if (extraBytes > std::numeric_limits<std::uint16_t>::max()) {
        throw Error(
            fmt::format("{}-byte records do not fit LAS (at most 65535 bytes)", recordLength));
    }
    if (extraBytes > 0) {
        layout.items.push_back(
            {ItemType::Byte14, static_cast<std::uint16_t>(extraBytes), layout.items[0].version});
        layout.recordLength = recordLength;
    }
    return layout;
}

std::vector<std::byte> laszipRecordPayload(const LazLayout& layout) {
    std::vector<std::byte> payload;
    appendLittleEndian(payload, layout.compressor);
    appendLittleEndian(payload, kArithmeticCoder);
    appendLittleEndian(payload, kLaszipVersionMajor);
    appendLittleEndian(payload, kLaszipVersionMinor);
    appendLittleEndian(payload, kLaszipRevision);
    appendLittleEndian(payload, std::uint32_t{0});  // options
    appendLittleEndian(payload, layout.chunkSize);
    appendLittleEndian(payload, std::int64_t{-1});  // no special EVLRs: their count and offset
    appendLittleEndian(payload, std::int64_t{-1});
    appendLittleEndian(payload, static_cast<std::uint16_t>(layout.items.size()));
    for (const ItemSpec& item : layout.items) {
        appendLittleEndian(payload, static_cast<std::uint16_t>(item.type));
        appendLittleEndian(payload, item.size);
        appendLittleEndian(payload, item.version);
    }
    return payload;
}

ChunkEncoder::ChunkEncoder(const LazLayout& layout) : layout_(layout) {
    if (layout.compressor != kCompressorLayeredChunked) {
        throw Error(
            fmt::format("the LAZ encoder writes layered chunks (compressor 3), not "
                        "compressor {}",
                        layout.compressor));
    }
    for (const ItemSpec& item : layout.items) {
        items_.push_back(makeLayeredItemEncoder(item));
    }
}

ChunkEncoder::~ChunkEncoder() = default;

std::vector<std::byte> ChunkEncoder::encode(std::span<const std::byte> records) {
    const std::size_t recordLength = layout_.recordLength;
    if (records.empty()) {
        throw Error("a LAZ chunk needs at least one point; this one has none");
    }
    if (records.size() % recordLength != 0) {
        throw Error(
            fmt::format("{} bytes of point records are not a whole number of {}-byte "
                        "records",
                        records.size(), recordLength));
    }
    const std::uint32_t pointCount = checkedUint32(records.size() / recordLength, "points");

    // The first point is stored raw and starts every item; the others are coded.
    std::uint32_t context = 0;
    std::size_t offset = 0;
    for (std::size_t k = 0; k < items_.size(); ++k) {
        items_[k]->start(records.data() + offset, context);
        offset += layout_.items[k].size;
    }
    for (std::uint32_t i = 1; i < pointCount; ++i) {
        const std::byte* record = records.data() + std::size_t{i} * recordLength;
        std::size_t itemOffset = 0;
        context = 0;  // as the decoder: POINT14 sets it only where the channel changes
        for (std::size_t k = 0; k < items_.size(); ++k) {
            items_[k]->encode(record + itemOffset, context);
            itemOffset += layout_.items[k].size;
        }
    }
    layers_.clear();
    for (const auto& item : items_) {
        item->finish(layers_);
    }

    std::size_t layerBytes = 0;
    for (const std::vector<std::byte>& layer : layers_) {
        layerBytes += layer.size();
    }
    std::vector<std::byte> chunk;
    chunk.reserve(recordLength + kChunkCountSize + kLayerSizeSize * layers_.size() + layerBytes);
    chunk.insert(chunk.end(), records.begin(), records.begin() + recordLength);
    appendLittleEndian(chunk, pointCount);
    for (const std::vector<std::byte>& layer : layers_) {
        appendLittleEndian(chunk, checkedUint32(layer.size(), "bytes in one layer"));
    }
    for (const std::vector<std::byte>& layer : layers_) {
        chunk.insert(chunk.end(), layer.begin(), layer.end());
    }
    return chunk;
}

std::vector<std::byte> encodeChunkTable(std::span<const Chunk> chunks, bool variableChunks) {
    std::vector<std::byte> table;
    appendLittleEndian(table, std::uint32_t{0});  // version
    appendLittleEndian(table, checkedUint32(chunks.size(), "chunks in its table"));
    ArithmeticEncoder encoder;
    IntegerCompressor integers(32, 2);
    std::int32_t lastCount = 0;
    std::int32_t lastSize = 0;
    for (const Chunk& chunk : chunks) {
        if (variableChunks) {
            const auto count = static_cast<std::int32_t>(checkedUint32(chunk.pointCount, "points"));
            integers.compress(encoder, lastCount, count, 0);
            lastCount = count;
        }
        const auto size = static_cast<std::int32_t>(checkedUint32(chunk.byteSize, "bytes"));
        integers.compress(encoder, lastSize, size, 1);
        lastSize = size;
    }
    const std::vector<std::byte> coded = encoder.finish();
    table.insert(table.end(), coded.begin(), coded.end());
    return table;
}

}  // namespace subscan::laz
