#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "io/laz/LazDecoder.h"

namespace subscan {

/// A variable length record of a LAS file, or an extended one (after the point data).
struct LasVlr {
    std::string userId;  // at most 16 bytes
    std::uint16_t recordId = 0;
    std::string description;  // at most 32 bytes
    std::vector<std::byte> payload;
};

/// What a LAZ file is made of: a LAS 1.4 file's parts, its point records uncompressed.
struct LazFileContents {
    /// The LAS 1.4 public header block (375 bytes). The fields that describe the points must be
    /// right: version 1.4, point format 6, 7 or 8, record length, the 64-bit point count, scale,
    /// offset, bounds. The writer sets those the file's layout decides: the point format's
    /// compression bit, header size, offset to the point data, the VLR and EVLR counts, the
    /// first EVLR's offset, and the legacy point counts (0 for point formats 6-10).
    std::vector<std::byte> header;
    /// Written in this order before the point data, followed by the laszip VLR.
    std::vector<LasVlr> vlrs;
    /// The point records as an uncompressed LAS file stores them.
    std::span<const std::byte> records;
    /// The points of each chunk, in record order (COPC: one chunk per octree node); each > 0.
    std::vector<std::uint64_t> chunkPointCounts;
    /// Written after the chunk table (COPC's hierarchy).
    std::vector<LasVlr> extendedVlrs;
};

/// Where the parts of an encoded LAZ file lie.
struct LazFileLayout {
    std::vector<laz::Chunk> chunks;
    std::uint64_t chunkTableOffset = 0;
    std::uint64_t firstExtendedVlrOffset = 0;  // the end of the chunk table
};

/// The bytes of a LAZ 1.4 file (layered chunks, variable chunk sizes; see io/laz/LazEncoder.h)
/// of `contents`. Throws subscan::Error naming what does not fit: a header that is not LAS 1.4
/// of point format 6-8 or disagrees with the records, chunk counts that do not add up to them,
/// a VLR too large for its 16-bit length.
std::vector<std::byte> encodeLazFile(const LazFileContents& contents,
                                     LazFileLayout* layout = nullptr);

/// The bytes before a LAZ 1.4 file's first chunk: `header` (as LazFileContents::header) with
/// the fields the layout decides set, `vlrs`, the laszip VLR of `layout`, then the chunk table's
/// offset (the point data's first 8 bytes). A writer that appends chunks as they come makes it
/// once to learn its size (it does not depend on the offsets) and again when the chunk table and
/// EVLRs are placed.
std::vector<std::byte> encodeLazPrefix(std::span<const std::byte> header,
                                       std::span<const LasVlr> vlrs, const laz::LazLayout& layout,
                                       std::uint64_t chunkTableOffset,
                                       std::uint64_t firstExtendedVlrOffset,
                                       std::uint32_t extendedVlrCount);

/// Appends `vlr` as LAS stores it: a VLR's 54-byte header (16-bit length) or an EVLR's 60-byte
/// one (64-bit length), then the payload. Throws subscan::Error for a user id or description
/// too long or, for a VLR, a payload beyond 65,535 bytes.
void appendLasVlr(std::vector<std::byte>& out, const LasVlr& vlr, bool extended);

/// Writes encodeLazFile's bytes to `path` atomically (see writeFileAtomically); errors name it.
LazFileLayout writeLaz(const std::filesystem::path& path, const LazFileContents& contents);

}  // namespace subscan
