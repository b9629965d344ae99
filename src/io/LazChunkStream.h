#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "io/InputFile.h"
#include "io/LasHeader.h"
#include "io/laz/LazDecoder.h"

namespace subscan {

/// The LAZ chunk table of a file read in pieces (what laz::readChunkTable does for a file in
/// memory): where each chunk lies and how many points it holds, checked against the file and
/// the header's point count. COPC files list every node as a chunk here too.
std::vector<laz::Chunk> readLazChunkTable(const InputFile& file, const LasHeader& header,
                                          const laz::LazLayout& layout);

/// The point records of a LAZ file's chunks in file order, each chunk read and decoded when its
/// turn nears: up to `threads` chunks decode at once on worker threads, and at most twice that
/// many are held (read, decoding or decoded and waiting), whatever the file's size.
class LazChunkStream {
  public:
    /// `file` must outlive the stream. `threads` 0 uses every core; 1 decodes on the caller's
    /// thread.
    LazChunkStream(const InputFile& file, laz::LazLayout layout, std::vector<laz::Chunk> chunks,
                   unsigned threads);
    ~LazChunkStream();
    LazChunkStream(const LazChunkStream&) = delete;
    LazChunkStream& operator=(const LazChunkStream&) = delete;

    /// Replaces `records` with the next chunk's records and returns true, or empties it and
    /// returns false after the last chunk. Throws subscan::Error naming the chunk that cannot be
    /// read or decoded.
    bool next(std::vector<std::byte>& records);

  private:
    enum class State { Waiting, Decoding, Done };
    struct Slot {
        std::size_t chunk = 0;
        State state = State::Waiting;
        std::vector<std::byte> records;
        std::exception_ptr error;
    };

    /// Reads and decodes chunk `index`; throws subscan::Error naming it.
    std::vector<std::byte> decode(std::size_t index) const;
    void work();
    void schedule();  // with the lock held: fills the window up to its size

    const InputFile& file_;
    laz::LazLayout layout_;
    std::vector<laz::Chunk> chunks_;
    std::size_t window_;
    std::size_t nextToSchedule_ = 0;
    std::size_t nextToReturn_ = 0;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Slot> slots_;  // in chunk order; workers keep pointers to slots being decoded
    bool stopping_ = false;
    std::vector<std::jthread> workers_;  // last: joined before the state above goes
};

}  // namespace subscan
