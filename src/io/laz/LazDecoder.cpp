#include "io/laz/LazDecoder.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/IntegerDecompressor.h"

namespace subscan::laz {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the LAZ item decoders store fields in host byte order");

const char* itemName(ItemType type) {
    switch (type) {
        case ItemType::Byte:
            return "BYTE";
        case ItemType::Point10:
            return "POINT10";
        case ItemType::GpsTime11:
            return "GPSTIME11";
        case ItemType::Rgb12:
            return "RGB12";
        case ItemType::WavePacket13:
            return "WAVEPACKET13";
        case ItemType::Point14:
            return "POINT14";
        case ItemType::Rgb14:
            return "RGB14";
        case ItemType::RgbNir14:
            return "RGBNIR14";
        case ItemType::WavePacket14:
            return "WAVEPACKET14";
        case ItemType::Byte14:
            return "BYTE14";
    }
    return "unknown";
}

/// The item decoders of one thread, reused from chunk to chunk (models are reset, not rebuilt).
class ChunkDecoder {
  public:
    explicit ChunkDecoder(const LazLayout& layout) : layout_(layout) {
        for (const ItemSpec& item : layout.items) {
            if (layout.compressor == kCompressorPointwiseChunked) {
                pointwise_.push_back(makePointwiseItemDecoder(item));
            } else {
                layered_.push_back(makeLayeredItemDecoder(item));
            }
        }
    }

    void decode(std::span<const std::byte> chunk, std::uint64_t pointCount, std::byte* records) {
        if (pointCount == 0) {
            return;
        }
        const std::size_t recordLength = layout_.recordLength;
        if (chunk.size() < recordLength) {
            throw Error(fmt::format("it has {} bytes, fewer than its first {}-byte point",
                                    chunk.size(), recordLength));
        }
        std::memcpy(records, chunk.data(), recordLength);  // the first point is stored raw
        if (layout_.compressor == kCompressorPointwiseChunked) {
            decodePointwise(chunk.subspan(recordLength), pointCount, records);
        } else {
            decodeLayered(chunk.subspan(recordLength), pointCount, records);
        }
    }

  private:
    void decodePointwise(std::span<const std::byte> stream, std::uint64_t pointCount,
                         std::byte* records) {
        std::size_t offset = 0;
        for (const auto& item : pointwise_) {
            item->start(records + offset);
            offset += layout_.items[&item - pointwise_.data()].size;
        }
        if (pointCount == 1) {
            return;
        }
        ArithmeticDecoder decoder(stream);
        for (std::uint64_t i = 1; i < pointCount; ++i) {
            std::byte* record = records + i * layout_.recordLength;
            std::size_t itemOffset = 0;
            for (std::size_t k = 0; k < pointwise_.size(); ++k) {
                pointwise_[k]->decode(decoder, record + itemOffset);
                itemOffset += layout_.items[k].size;
            }
        }
    }

    void decodeLayered(std::span<const std::byte> rest, std::uint64_t pointCount,
                       std::byte* records) {
        std::size_t layerCount = 0;
        for (const auto& item : layered_) {
            layerCount += item->layerCount();
        }
        const std::size_t tableSize = 4 + 4 * layerCount;
        if (rest.size() < tableSize) {
            throw Error(fmt::format(
                "it ends before its point count and the byte counts of its {} layers", layerCount));
        }
        const auto storedCount = loadLittleEndian<std::uint32_t>(rest.data());
        if (storedCount != pointCount) {
            throw Error(fmt::format("it says it holds {} points, but the chunk table says {}",
                                    storedCount, pointCount));
        }
        layers_.resize(layerCount);
        std::size_t position = tableSize;
        for (std::size_t i = 0; i < layerCount; ++i) {
            const auto bytes = loadLittleEndian<std::uint32_t>(rest.data() + 4 + 4 * i);
            if (rest.size() - position < bytes) {
                throw Error(
                    fmt::format("its layer {} of {} declares {} bytes, beyond the end of the chunk",
                                i + 1, layerCount, bytes));
            }
            layers_[i] = rest.subspan(position, bytes);
            position += bytes;
        }

        std::uint32_t context = 0;
        std::size_t firstLayer = 0;
        std::size_t offset = 0;
        for (std::size_t k = 0; k < layered_.size(); ++k) {
            const std::size_t count = layered_[k]->layerCount();
            layered_[k]->start(records + offset, std::span(layers_).subspan(firstLayer, count),
                               context);
            firstLayer += count;
            offset += layout_.items[k].size;
        }
        for (std::uint64_t i = 1; i < pointCount; ++i) {
            std::byte* record = records + i * layout_.recordLength;
            std::size_t itemOffset = 0;
            // Every point starts from context 0, which POINT14 changes only where the scanner
            // channel changes (LASzip's reader, and so its writer, work so).
            context = 0;
            for (std::size_t k = 0; k < layered_.size(); ++k) {
                layered_[k]->decode(record + itemOffset, context);
                itemOffset += layout_.items[k].size;
            }
        }
    }

    const LazLayout& layout_;
    std::vector<std::unique_ptr<PointwiseItemDecoder>> pointwise_;
    std::vector<std::unique_ptr<LayeredItemDecoder>> layered_;
    std::vector<std::span<const std::byte>> layers_;
};

}  // namespace

std::string chunkName(std::size_t index, std::size_t count, const Chunk& chunk) {
    return fmt::format("the LAZ chunk {} of {} (at byte {})", index + 1, count, chunk.offset);
}

std::vector<ItemSpec> pointFormatItems(int pointFormat) {
    const ItemSpec point10{ItemType::Point10, 20, 2};
    const ItemSpec gpsTime{ItemType::GpsTime11, 8, 2};
    const ItemSpec rgb12{ItemType::Rgb12, 6, 2};
    const ItemSpec wave13{ItemType::WavePacket13, 29, 1};
    const ItemSpec point14{ItemType::Point14, 30, 3};
    const ItemSpec rgb14{ItemType::Rgb14, 6, 3};
    const ItemSpec rgbNir14{ItemType::RgbNir14, 8, 3};
    const ItemSpec wave14{ItemType::WavePacket14, 29, 3};
    switch (pointFormat) {
        case 0:
            return {point10};
        case 1:
            return {point10, gpsTime};
        case 2:
            return {point10, rgb12};
        case 3:
            return {point10, gpsTime, rgb12};
        case 4:
            return {point10, gpsTime, wave13};
        case 5:
            return {point10, gpsTime, rgb12, wave13};
        case 6:
            return {point14};
        case 7:
            return {point14, rgb14};
        case 8:
            return {point14, rgbNir14};
        case 9:
            return {point14, wave14};
        default:
            return {point14, rgbNir14, wave14};
    }
}

LazLayout parseLaszipRecord(std::span<const std::byte> payload, int pointFormat,
                            std::size_t recordLength) {
    if (payload.size() < kLaszipRecordHeaderSize) {
        throw Error(fmt::format("the laszip VLR has {} bytes, fewer than the {} it needs",
                                payload.size(), kLaszipRecordHeaderSize));
    }
    LazLayout layout;
    layout.compressor = loadLittleEndian<std::uint16_t>(payload.data());
    const auto coder = loadLittleEndian<std::uint16_t>(payload.data() + 2);
    const auto majorVersion = static_cast<int>(payload[4]);
    const auto minorVersion = static_cast<int>(payload[5]);
    layout.chunkSize = loadLittleEndian<std::uint32_t>(payload.data() + 12);
    const auto itemCount = loadLittleEndian<std::uint16_t>(payload.data() + 32);
    if (coder != 0) {
        throw Error(fmt::format("the LAZ coder {} is unknown (only 0, arithmetic, exists)", coder));
    }
    if (layout.compressor != kCompressorPointwiseChunked &&
        layout.compressor != kCompressorLayeredChunked) {
        throw Error(fmt::format(
            "the LAZ compressor {} (written by LASzip {}.{}) is not supported (supported: 2, "
            "pointwise chunks, and 3, layered chunks)",
            layout.compressor, majorVersion, minorVersion));
    }
    if (layout.chunkSize == 0) {
        throw Error("the laszip VLR declares a chunk size of 0 points");
    }
    if (payload.size() < kLaszipRecordHeaderSize + kLaszipItemSize * itemCount) {
        throw Error(fmt::format("the laszip VLR declares {} items but has room for only {}",
                                itemCount,
                                (payload.size() - kLaszipRecordHeaderSize) / kLaszipItemSize));
    }

    const std::vector<ItemSpec> expected = pointFormatItems(pointFormat);
    const bool layered = layout.compressor == kCompressorLayeredChunked;
    const std::uint16_t wantedVersion = layered ? 3 : 2;
    const ItemType extraBytes = pointFormat >= 6 ? ItemType::Byte14 : ItemType::Byte;
    for (std::uint16_t i = 0; i < itemCount; ++i) {
        const std::byte* p = payload.data() + kLaszipRecordHeaderSize + kLaszipItemSize * i;
        ItemSpec item{static_cast<ItemType>(loadLittleEndian<std::uint16_t>(p)),
                      loadLittleEndian<std::uint16_t>(p + 2),
                      loadLittleEndian<std::uint16_t>(p + 4)};
        const bool isExtra = i >= expected.size();
        const ItemType wantedType = isExtra ? extraBytes : expected[i].type;
        if (item.type == ItemType::WavePacket13 || item.type == ItemType::WavePacket14) {
            throw Error(
                "LAZ files with wave packets (point formats 4, 5, 9 and 10) are not supported");
        }
        if (item.type != wantedType) {
            throw Error(
                fmt::format("the laszip VLR's item {} is {}, but point format {} needs {} there",
                            i + 1, itemName(item.type), pointFormat, itemName(wantedType)));
        }
        if (item.version != wantedVersion) {
            throw Error(fmt::format(
                "the LAZ item {} has coder version {}; supported: version {} with compressor {} "
                "({})",
                itemName(item.type), item.version, wantedVersion, layout.compressor,
                item.version < 2    ? "LASzip 1.x items are not"
                : item.version == 4 ? "version 4 is not"
                                    : "the versions must match the compressor"));
        }
        const std::uint16_t wantedSize = isExtra ? item.size : expected[i].size;
        if (item.size != wantedSize || item.size == 0) {
            throw Error(fmt::format("the LAZ item {} declares {} bytes; it has {}",
                                    itemName(item.type), item.size, wantedSize));
        }
        layout.items.push_back(item);
        layout.recordLength += item.size;
    }
    if (layout.items.size() < expected.size()) {
        throw Error(fmt::format("the laszip VLR lists {} items; point format {} needs {}",
                                layout.items.size(), pointFormat, expected.size()));
    }
    if (layout.recordLength != recordLength) {
        throw Error(fmt::format(
            "the laszip VLR's items make {}-byte points, but the LAS header says {} bytes",
            layout.recordLength, recordLength));
    }
    return layout;
}

std::uint64_t checkedChunkTableOffset(std::int64_t offset, std::uint64_t chunksStart,
                                      std::uint64_t fileSize) {
    if (offset < static_cast<std::int64_t>(chunksStart) ||
        static_cast<std::uint64_t>(offset) + kChunkTableHeaderSize > fileSize) {
        throw Error(fmt::format(
            "the LAZ chunk table offset {} lies outside the point data (bytes {} to {}; file "
            "truncated?)",
            offset, chunksStart, fileSize));
    }
    return static_cast<std::uint64_t>(offset);
}

std::vector<Chunk> decodeChunkTable(std::span<const std::byte> table, std::uint64_t chunksStart,
                                    std::uint64_t tableOffset, std::uint64_t fileSize,
                                    const LazLayout& layout, std::uint64_t pointCount) {
    if (table.size() < kChunkTableHeaderSize) {
        throw Error("the LAZ chunk table is cut off before its chunk count");
    }
    const auto version = loadLittleEndian<std::uint32_t>(table.data());
    const auto chunkCount = loadLittleEndian<std::uint32_t>(table.data() + 4);
    if (version != 0) {
        throw Error(fmt::format("the LAZ chunk table has version {}; only 0 exists", version));
    }
    const bool variable = layout.chunkSize == kVariableChunkSize;
    const std::uint64_t expectedChunks =
        variable ? chunkCount : (pointCount + layout.chunkSize - 1) / layout.chunkSize;
    // Every chunk takes at least a byte, so a count above the file size is corrupt (and must not
    // allocate).
    if (chunkCount != expectedChunks || chunkCount > fileSize) {
        throw Error(fmt::format(
            "the LAZ chunk table lists {} chunks, but {} points in chunks of {} make {}",
            chunkCount, pointCount, layout.chunkSize, expectedChunks));
    }

    std::vector<Chunk> chunks(chunkCount);
    if (chunkCount > 0) {
        ArithmeticDecoder decoder(table.subspan(kChunkTableHeaderSize));
        IntegerDecompressor integers(32, 2);
        integers.reset();
        std::int32_t lastCount = 0;
        std::int32_t lastSize = 0;
        for (Chunk& chunk : chunks) {
            if (variable) {
                lastCount = integers.decompress(decoder, lastCount, 0);
                chunk.pointCount = static_cast<std::uint32_t>(lastCount);
            }
            lastSize = integers.decompress(decoder, lastSize, 1);
            chunk.byteSize = static_cast<std::uint32_t>(lastSize);
        }
    }
    std::uint64_t offset = chunksStart;
    std::uint64_t points = 0;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        Chunk& chunk = chunks[i];
        chunk.offset = offset;
        if (!variable) {
            chunk.pointCount = std::min<std::uint64_t>(layout.chunkSize, pointCount - points);
        }
        if (chunk.byteSize > tableOffset - offset) {
            throw Error(fmt::format(
                "the LAZ chunk table says chunk {} of {} has {} bytes, which reach past the "
                "chunk table",
                i + 1, chunks.size(), chunk.byteSize));
        }
        if (chunk.pointCount > kMostLazPointsPerByte * chunk.byteSize) {
            throw Error(fmt::format("{} claims {} points in {} bytes, far more than LAZ can hold",
                                    chunkName(i, chunks.size(), chunk), chunk.pointCount,
                                    chunk.byteSize));
        }
        offset += chunk.byteSize;
        points += chunk.pointCount;
    }
    if (points != pointCount) {
        throw Error(fmt::format(
            "the LAZ chunk table's chunks hold {} points, but the LAS header declares {}", points,
            pointCount));
    }
    return chunks;
}

std::vector<Chunk> readChunkTable(std::span<const std::byte> file, std::size_t pointDataOffset,
                                  const LazLayout& layout, std::uint64_t pointCount) {
    if (file.size() - pointDataOffset < 8) {
        throw Error("the LAZ point data is shorter than its 8-byte chunk table offset");
    }
    const std::uint64_t chunksStart = pointDataOffset + 8;
    auto stored = loadLittleEndian<std::int64_t>(file.data() + pointDataOffset);
    if (stored == -1) {
        // Written by a streaming compressor: the offset was appended at the end of the file.
        stored = loadLittleEndian<std::int64_t>(file.data() + file.size() - 8);
    }
    const std::uint64_t tableOffset = checkedChunkTableOffset(stored, chunksStart, file.size());
    return decodeChunkTable(file.subspan(static_cast<std::size_t>(tableOffset)), chunksStart,
                            tableOffset, file.size(), layout, pointCount);
}

void decodeChunk(std::span<const std::byte> chunk, std::uint64_t pointCount,
                 const LazLayout& layout, std::byte* records) {
    ChunkDecoder(layout).decode(chunk, pointCount, records);
}

void decodeChunks(std::span<const std::byte> file, const LazLayout& layout,
                  std::span<const Chunk> chunks, std::span<std::byte> records, unsigned threads,
                  const std::function<void(std::uint64_t)>& progress) {
    std::vector<std::uint64_t> firstRecord(chunks.size() + 1, 0);
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        if (chunks[i].offset > file.size() || chunks[i].byteSize > file.size() - chunks[i].offset) {
            throw Error(fmt::format("{} lies beyond the end of the file",
                                    chunkName(i, chunks.size(), chunks[i])));
        }
        firstRecord[i + 1] = firstRecord[i] + chunks[i].pointCount;
    }
    if (firstRecord.back() * layout.recordLength != records.size()) {
        throw Error(fmt::format("the LAZ chunks hold {} points, not the {} expected",
                                firstRecord.back(), records.size() / layout.recordLength));
    }

    if (threads == 0) {
        threads = std::max(1u, std::thread::hardware_concurrency());
    }
    threads = static_cast<unsigned>(std::min<std::size_t>(threads, chunks.size()));
    std::atomic<std::size_t> nextChunk{0};
    std::atomic<bool> failed{false};
    std::mutex mutex;  // guards firstError, pointsDone and progress calls
    std::exception_ptr firstError;
    std::uint64_t pointsDone = 0;
    const auto work = [&] {
        try {
            ChunkDecoder decoder(layout);
            for (std::size_t i = nextChunk++; i < chunks.size() && !failed; i = nextChunk++) {
                const Chunk& chunk = chunks[i];
                try {
                    decoder.decode(file.subspan(chunk.offset, chunk.byteSize), chunk.pointCount,
                                   records.data() + firstRecord[i] * layout.recordLength);
                } catch (const Error& error) {
                    throw Error(fmt::format("{} cannot be decoded: {}",
                                            chunkName(i, chunks.size(), chunk), error.what()));
                }
                const std::lock_guard lock(mutex);
                pointsDone += chunk.pointCount;
                if (progress) {
                    progress(pointsDone);
                }
            }
        } catch (...) {
            const std::lock_guard lock(mutex);
            if (!firstError) {
                firstError = std::current_exception();
            }
            failed = true;
        }
    };
    std::vector<std::jthread> workers;
    for (unsigned t = 1; t < threads; ++t) {
        workers.emplace_back(work);
    }
    work();
    workers.clear();  // joins
    if (firstError) {
        std::rethrow_exception(firstError);
    }
}

}  // namespace subscan::laz
