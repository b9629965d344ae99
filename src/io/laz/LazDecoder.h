#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "io/laz/LazItems.h"

// LAZ: LAS point data compressed by LASzip in independent chunks (Isenburg 2013; LASzip's
// design notes). The header and VLRs stay LAS; the laszip VLR describes the items of a point
// record and the chunking; a table after the chunks gives each chunk's byte size (and, with
// variable chunks, its point count). This module turns the chunks back into the uncompressed
// point records, so the LAS reader decodes LAZ and LAS records with the same code.
namespace subscan::laz {

inline constexpr std::uint16_t kCompressorPointwiseChunked = 2;
inline constexpr std::uint16_t kCompressorLayeredChunked = 3;
/// Chunk size of files whose chunks each store their own point count in the chunk table.
inline constexpr std::uint32_t kVariableChunkSize = 0xFFFFFFFFu;

struct LazLayout {
    std::uint16_t compressor = 0;
    std::uint32_t chunkSize = 0;
    std::vector<ItemSpec> items;
    std::size_t recordLength = 0;  // the sum of the item sizes
};

/// Where one chunk lies in the file and how many points it holds.
struct Chunk {
    std::uint64_t offset = 0;
    std::uint64_t byteSize = 0;
    std::uint64_t pointCount = 0;
};

/// The laszip VLR's payload: a header of this size (up to and including the item count), then
/// each item's type, size and version.
inline constexpr std::size_t kLaszipRecordHeaderSize = 34;
inline constexpr std::size_t kLaszipItemSize = 6;

/// The items a record of `pointFormat` (0-10) consists of, before any extra bytes (LAS 1.4 R15
/// section 2.6 restated as LASzip items): their sizes, and the coder versions subscan reads.
std::vector<ItemSpec> pointFormatItems(int pointFormat);

/// Parses the payload of the laszip VLR (user "laszip encoded", record 22204) and checks it
/// against the header's point format (0-10) and record length. Throws subscan::Error naming the
/// unsupported variant (compressor, item type or version).
LazLayout parseLaszipRecord(std::span<const std::byte> payload, int pointFormat,
                            std::size_t recordLength);

/// "the LAZ chunk 3 of 11 (at byte 123456)", for error sentences.
std::string chunkName(std::size_t index, std::size_t count, const Chunk& chunk);

/// LASzip compresses hardly below two bytes a point: a header or chunk that claims more than
/// this many points per compressed byte is corrupt, and must not make a reader allocate its
/// records.
inline constexpr std::uint64_t kMostLazPointsPerByte = 64;

/// The chunk table starts with its version (0) and chunk count; each chunk's byte size (and, for
/// variable chunks, point count) follows, coded as 32-bit integers predicted from the previous
/// chunk's.
inline constexpr std::size_t kChunkTableHeaderSize = 8;
/// The most bytes of a chunk table of `chunkCount` chunks the decoder may read, header included
/// (a coded 32-bit value takes at most 5 bytes; twice that per value bounds it).
inline std::uint64_t mostChunkTableBytes(std::uint32_t chunkCount) {
    return std::uint64_t{chunkCount} * 2 * 10 + kChunkTableHeaderSize;
}

/// Checks the chunk table's offset, as stored at the point data's start (or, for -1, at the
/// file's end), against the point data (`chunksStart`, just after that offset) and the file.
std::uint64_t checkedChunkTableOffset(std::int64_t offset, std::uint64_t chunksStart,
                                      std::uint64_t fileSize);

/// Decodes the chunk table from `table`, its bytes from the table's start on (they may run on
/// past it: the decoder reads no further than the entries need). The chunks lie from
/// `chunksStart` up to the table at `tableOffset` in a file of `fileSize` bytes. Checks the
/// version, the chunk count against `pointCount`, that every chunk ends before the table and
/// holds no more points than LAZ can fit in its bytes, and that the chunks hold `pointCount`
/// points in all.
std::vector<Chunk> decodeChunkTable(std::span<const std::byte> table, std::uint64_t chunksStart,
                                    std::uint64_t tableOffset, std::uint64_t fileSize,
                                    const LazLayout& layout, std::uint64_t pointCount);

/// Reads the chunk table of a file in memory. `pointDataOffset` is where the header says the
/// point data starts: the table's offset is stored there, the first chunk follows it.
std::vector<Chunk> readChunkTable(std::span<const std::byte> file, std::size_t pointDataOffset,
                                  const LazLayout& layout, std::uint64_t pointCount);

/// Decodes `chunks` (independent of each other) into consecutive point records: chunk i's first
/// record goes right after the records of chunks 0..i-1. `threads` 0 uses every core.
/// `progress` (may be empty) receives the number of points decoded so far, from any thread
/// (calls are serialised). Errors name the chunk.
void decodeChunks(std::span<const std::byte> file, const LazLayout& layout,
                  std::span<const Chunk> chunks, std::span<std::byte> records, unsigned threads,
                  const std::function<void(std::uint64_t)>& progress);

/// Decodes one chunk into `pointCount` records at `records`; what decodeChunks does per chunk.
/// Exposed for tests and for COPC nodes read one at a time.
void decodeChunk(std::span<const std::byte> chunk, std::uint64_t pointCount,
                 const LazLayout& layout, std::byte* records);

}  // namespace subscan::laz
