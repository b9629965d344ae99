#include "io/LazChunkStream.h"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"

namespace subscan {

std::vector<laz::Chunk> readLazChunkTable(const InputFile& file, const LasHeader& header,
                                          const laz::LazLayout& layout) {
    const std::uint64_t chunksStart = header.pointDataOffset + 8;
    if (file.size() < chunksStart) {
        throw Error("the LAZ point data is shorter than its 8-byte chunk table offset");
    }
    std::vector<std::byte> word = file.read(header.pointDataOffset, 8);
    auto stored = loadLittleEndian<std::int64_t>(word.data());
    if (stored == -1) {
        // Written by a streaming compressor: the offset was appended at the end of the file.
        word = file.read(file.size() - 8, 8);
        stored = loadLittleEndian<std::int64_t>(word.data());
    }
    const std::uint64_t table = laz::checkedChunkTableOffset(stored, chunksStart, file.size());
    // The chunk count first, to read no more of the table than its entries can take.
    const std::vector<std::byte> head = file.read(table, laz::kChunkTableHeaderSize);
    const auto chunkCount = loadLittleEndian<std::uint32_t>(head.data() + 4);
    const std::vector<std::byte> bytes =
        file.read(table, static_cast<std::size_t>(
                             std::min(file.size() - table, laz::mostChunkTableBytes(chunkCount))));
    return laz::decodeChunkTable(bytes, chunksStart, table, file.size(), layout, header.pointCount);
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
                                laz::chunkName(index, chunks_.size(), chunk), error.what()));
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
