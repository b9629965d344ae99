#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "io/laz/LazDecoder.h"
#include "io/laz/LazItems.h"

// LAZ encoding, the mirror of LazDecoder: LAS 1.4 point records of formats 6, 7 and 8 (with any
// number of extra bytes) to LASzip's layered chunks (compressor 3; items POINT14, RGB14 or
// RGBNIR14, and BYTE14, version 3), the chunk table and the payload of the laszip VLR. Chunks
// hold any number of points (variable chunks: COPC writes one chunk per octree node).
namespace subscan::laz {

/// The layout of layered, variable-chunk LAZ records of LAS 1.4 `pointFormat` (6, 7 or 8) and
/// `recordLength` bytes: the format's items, then the extra bytes as one BYTE14 item. Throws
/// subscan::Error for another format or a record shorter than the format's.
LazLayout layeredLazLayout(int pointFormat, std::size_t recordLength);

/// The payload of the laszip VLR (user "laszip encoded", record 22204) describing `layout`, what
/// parseLaszipRecord reads back. It names LASzip 3.4 revision 3, the version whose format the
/// items follow, as LASzip and laz-perf write it.
std::vector<std::byte> laszipRecordPayload(const LazLayout& layout);

/// Encodes the chunks of a layered layout one at a time, reusing its models from chunk to chunk
/// (one encoder per thread).
class ChunkEncoder {
  public:
    explicit ChunkEncoder(const LazLayout& layout);
    ~ChunkEncoder();
    ChunkEncoder(const ChunkEncoder&) = delete;
    ChunkEncoder& operator=(const ChunkEncoder&) = delete;

    /// One chunk of `records` (whole records, at least one, fewer than 2^32): the first record
    /// raw, then the point count, the byte count of each layer and the layers. Throws
    /// subscan::Error for records that do not fit the layout.
    std::vector<std::byte> encode(std::span<const std::byte> records);

  private:
    LazLayout layout_;
    std::vector<std::unique_ptr<LayeredItemEncoder>> items_;
    std::vector<std::vector<std::byte>> layers_;
};

/// The chunk table that readChunkTable reads: version 0, the chunk count, then per chunk its
/// point count (variable chunks only) and byte size, each coded as a difference to the previous
/// chunk's. Throws subscan::Error for a count or size beyond 32 bits.
std::vector<std::byte> encodeChunkTable(std::span<const Chunk> chunks, bool variableChunks);

}  // namespace subscan::laz
