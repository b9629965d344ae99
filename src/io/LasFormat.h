#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

// Where LAS keeps what the LAS reader and the LAZ writer read and write: the public header
// block's fields (LAS 1.4 R15, table 3; the fields up to byte 227 sit at the same place in
// every version since 1.0) and the headers of VLRs and EVLRs (tables 13 and 17).
namespace subscan::las {

/// Byte offsets of the public header block fields, all little-endian.
namespace header_field {
inline constexpr std::size_t kFileSourceId = 4;
inline constexpr std::size_t kGlobalEncoding = 6;
inline constexpr std::size_t kVersionMajor = 24;
inline constexpr std::size_t kVersionMinor = 25;
inline constexpr std::size_t kSystemIdentifier = 26;    // 32 characters
inline constexpr std::size_t kGeneratingSoftware = 58;  // 32 characters
inline constexpr std::size_t kCreationDay = 90;         // day of the year, 1-366
inline constexpr std::size_t kCreationYear = 92;
inline constexpr std::size_t kHeaderSize = 94;
inline constexpr std::size_t kPointDataOffset = 96;
inline constexpr std::size_t kVlrCount = 100;
inline constexpr std::size_t kPointFormat = 104;
inline constexpr std::size_t kRecordLength = 105;
inline constexpr std::size_t kLegacyPointCount = 107;
inline constexpr std::size_t kLegacyReturnCounts = 111;  // five uint32
inline constexpr std::size_t kScale = 131;               // x, y, z doubles
inline constexpr std::size_t kOffset = 155;              // x, y, z doubles
inline constexpr std::size_t kBounds = 179;  // max x, min x, max y, min y, max z, min z doubles
inline constexpr std::size_t kFirstEvlrOffset = 235;  // LAS 1.4 only, from here on
inline constexpr std::size_t kEvlrCount = 243;
inline constexpr std::size_t kPointCount64 = 247;
inline constexpr std::size_t kReturnCounts64 = 255;  // fifteen uint64
}  // namespace header_field

/// Global encoding bit 0: GPS times are Adjusted Standard GPS time, not GPS week seconds.
inline constexpr std::uint16_t kStandardGpsTime = 1u << 0;

inline constexpr std::size_t kHeaderSizeUpTo12 = 227;
inline constexpr std::size_t kHeaderSize13 = 235;  // adds the waveform data offset
inline constexpr std::size_t kHeaderSize14 = 375;  // adds EVLRs and 64-bit point counts

/// A VLR: reserved (2 bytes), user id (16), record id (2), payload length (2), description
/// (32), then the payload. An EVLR's payload length has 8 bytes.
inline constexpr std::size_t kVlrHeaderSize = 54;
inline constexpr std::size_t kEvlrHeaderSize = 60;
inline constexpr std::size_t kVlrUserIdOffset = 2;
inline constexpr std::size_t kVlrUserIdSize = 16;
inline constexpr std::size_t kVlrRecordIdOffset = 18;
inline constexpr std::size_t kVlrLengthOffset = 20;
inline constexpr std::size_t kVlrDescriptionSize = 32;

/// laszip marks compressed point data with bit 7 of the point format byte (bit 6 too in its
/// layered-chunk variant) and describes the compressor in a VLR.
inline constexpr std::uint8_t kCompressionBits = 0xC0;
inline constexpr std::string_view kLaszipUserId = "laszip encoded";
inline constexpr std::uint16_t kLaszipRecordId = 22204;

}  // namespace subscan::las
