#include "io/LazChunkStream.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/laz/IntegerDecompressor.h"

namespace subscan {

namespace {

/// The table starts with its version (0) and chunk count; each chunk's byte size (and, for
/// variable chunks, point count) follows, coded as 32-bit integers predicted from the previous
/// chunk's (LASzip's chunk table, as laz::readChunkTable reads it).
constexpr std::size_t kTableHeaderSize = 8;
/// A coded 32-bit value takes at most 5 bytes; twice that per value bounds what to read.
constexpr std::size_t kMostTableBytesPerValue = 10;
/// LASzip compresses hardly below two bytes a point (see LasReader's same bound): a chunk that
/// claims more points per byte is corrupt and must not make us allocate its records.
constexpr std::uint64_t kMostPointsPerChunkByte = 64;

std::string lazChunkName(std::size_t index, std::size_t count, const laz::Chunk& chunk) {
    return fmt::format("the LAZ chunk {} of {} (at byte {})", index + 1, count, chunk.offset);
}

}  // namespace

std::vector<laz::Chunk> readLazChunkTable(const InputFile& file, const LasHeader& header,
                                          const laz::LazLayout& layout) {
    const std::uint64_t chunksStart = header.pointDataOffset + 8;
    if (file.size() < chunksStart) {
        throw Error("the LAZ point data is shorter than its 8-byte chunk table offset");
    }
    std::vector<std::byte> word = file.read(header.pointDataOffset, 8);
    auto tableOffset = loadLittleEndian<std::int64_t>(word.data());
    if (tableOffset == -1) {
        // Written by a streaming compressor: the offset was appended at the end of the file.
        word = file.read(file.size() - 8, 8);
        tableOffset = loadLittleEndian<std::int64_t>(word.data());
    }
    if (tableOffset < static_cast<std::int64_t>(chunksStart) ||
        static_cast<std::uint64_t>(tableOffset) + kTableHeaderSize > file.size()) {
        throw Error(fmt::format(
            "the LAZ chunk table offset {} lies outside the point data (bytes {} to {}; file "
            "truncated?)",
            tableOffset, chunksStart, file.size()));
    }
    const auto table = static_cast<std::uint64_t>(tableOffset);
    const std::vector<std::byte> tableHeader = file.read(table, kTableHeaderSize);
    const auto version = loadLittleEndian<std::uint32_t>(tableHeader.data());
    const auto chunkCount = loadLittleEndian<std::uint32_t>(tableHeader.data() + 4);
    if (version != 0) {
        throw Error(fmt::format("the LAZ chunk table has version {}; only 0 exists", version));
    }
    const bool variable = layout.chunkSize == laz::kVariableChunkSize;
    const std::uint64_t pointCount = header.pointCount;
    const std::uint64_t expected =
        variable ? chunkCount : (pointCount + layout.chunkSize - 1) / layout.chunkSize;
    // Every chunk takes at least a byte: a count beyond the file's size is corrupt (and must not
    // allocate).
    if (chunkCount != expected || chunkCount > file.size()) {
        throw Error(fmt::format(
            "the LAZ chunk table lists {} chunks, but {} points in chunks of {} make {}",
            chunkCount, pointCount, layout.chunkSize, expected));
    }

    std::vector<laz::Chunk> chunks(chunkCount);
    if (chunkCount > 0) {
        const std::uint64_t codedStart = table + kTableHeaderSize;
        // The coder reads no further than the values need; what follows the table (extended
        // VLRs, or nothing) is never decoded.
        const std::uint64_t most =
            std::uint64_t{chunkCount} * 2 * kMostTableBytesPerValue + kTableHeaderSize;
        std::vector<std::byte> coded(
            static_cast<std::size_t>(std::min(file.size() - codedStart, most)));
        file.read(codedStart, coded);
        laz::ArithmeticDecoder decoder(coded);
        laz::IntegerDecompressor integers(32, 2);
        integers.reset();
        std::int32_t count = 0;
        std::int32_t size = 0;
        for (laz::Chunk& chunk : chunks) {
            if (variable) {
                count = integers.decompress(decoder, count, 0);
                chunk.pointCount = static_cast<std::uint32_t>(count);
            }
            size = integers.decompress(decoder, size, 1);
            chunk.byteSize = static_cast<std::uint32_t>(size);
        }
    }

    std::uint64_t offset = chunksStart;
    std::uint64_t points = 0;
    for (std::size_t i = 0; i < chunks.size(); ++i) {
        laz::Chunk& chunk = chunks[i];
        chunk.offset = offset;
        if (!variable) {
            chunk.pointCount = std::min<std::uint64_t>(layout.chunkSize, pointCount - points);
        }
        if (chunk.byteSize > table - offset) {
            throw Error(fmt::format("{} has {} bytes, which reach past the chunk table at byte {}",
                                    lazChunkName(i, chunks.size(), chunk), chunk.byteSize, table));
        }
        if (chunk.pointCount > kMostPointsPerChunkByte * chunk.byteSize) {
            throw Error(fmt::format("{} claims {} points in {} bytes, far more than LAZ can hold",
                                    lazChunkName(i, chunks.size(), chunk), chunk.pointCount,
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

LazChunkStream::LazChunkStream(const InputFile& file, laz::LazLayout layout,
                               std::vector<laz::Chunk> chunks, unsigned threads)
    : file_(file), layout_(std::move(layout)), chunks_(std::move(chunks)) {
    if (threads == 0) {
        threads = std::max(1u, std::thread::hardware_concurrency());
    }
    threads = static_cast<unsigned>(std::min<std::size_t>(threads, chunks_.size()));
    // Two slots a thread: while the caller converts one chunk, every worker has the next.
    window_ = threads <= 1 ? 1 : 2 * std::size_t{threads};
    if (threads > 1) {
        for (unsigned t = 0; t < threads; ++t) {
            workers_.emplace_back([this] { work(); });
        }
    }
}

LazChunkStream::~LazChunkStream() {
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    workers_.clear();  // joins; a worker finishes the chunk in hand first
}

std::vector<std::byte> LazChunkStream::decode(std::size_t index) const {
    const laz::Chunk& chunk = chunks_[index];
    try {
        const std::vector<std::byte> compressed =
            file_.read(chunk.offset, static_cast<std::size_t>(chunk.byteSize));
        std::vector<std::byte> records(static_cast<std::size_t>(chunk.pointCount) *
                                       layout_.recordLength);
        laz::decodeChunk(compressed, chunk.pointCount, layout_, records.data());
        return records;
    } catch (const Error& error) {
        throw Error(fmt::format("{} cannot be decoded: {}",
                                lazChunkName(index, chunks_.size(), chunk), error.what()));
    }
}

void LazChunkStream::work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        Slot* slot = nullptr;
        changed_.wait(lock, [&] {
            const auto waiting = std::find_if(slots_.begin(), slots_.end(), [](const Slot& s) {
                return s.state == State::Waiting;
            });
            slot = waiting == slots_.end() ? nullptr : &*waiting;
            return stopping_ || slot != nullptr;
        });
        if (stopping_) {
            return;
        }
        slot->state = State::Decoding;
        const std::size_t index = slot->chunk;
        lock.unlock();
        std::vector<std::byte> records;
        std::exception_ptr error;
        try {
            records = decode(index);
        } catch (...) {
            error = std::current_exception();
        }
        lock.lock();
        // The caller takes a slot only once it is done, so `slot` is still in the window.
        slot->records = std::move(records);
        slot->error = error;
        slot->state = State::Done;
        changed_.notify_all();
    }
}

void LazChunkStream::schedule() {
    while (slots_.size() < window_ && nextToSchedule_ < chunks_.size()) {
        slots_.push_back({nextToSchedule_++, State::Waiting, {}, nullptr});
    }
}

bool LazChunkStream::next(std::vector<std::byte>& records) {
    if (nextToReturn_ == chunks_.size()) {
        records.clear();
        return false;
    }
    if (workers_.empty()) {
        records = decode(nextToReturn_++);
        return true;
    }
    std::unique_lock lock(mutex_);
    schedule();
    changed_.notify_all();
    changed_.wait(lock, [&] { return slots_.front().state == State::Done; });
    Slot slot = std::move(slots_.front());
    slots_.pop_front();
    ++nextToReturn_;
    schedule();
    lock.unlock();
    changed_.notify_all();
    if (slot.error) {
        std::rethrow_exception(slot.error);
    }
    records = std::move(slot.records);
    return true;
}

}  // namespace subscan
