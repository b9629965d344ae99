#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
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

/// Reads the chunk table. `pointDataOffset` is where the header says the point data starts: the
/// table's offset is stored there, the first chunk follows it. Checks that every chunk lies in
/// the file and that the chunks hold `pointCount` points in all.
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
