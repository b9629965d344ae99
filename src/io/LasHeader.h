#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include <glm/vec3.hpp>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// What a LAS point data record format holds before any extra bytes.
struct LasPointFormatLayout {
    std::size_t recordSize;
    std::optional<std::size_t> colorOffset;  // three uint16 (R, G, B) where the format has them
    int firstMinorVersion;                   // the LAS 1.x version that introduced the format
};

// LAS 1.4 R15, section 2.6: formats 0-5 extend the 20-byte legacy core, formats 6-10 the 30-byte
// core that LAS 1.4 introduced (wider return and class fields, 16-bit scan angle, GPS time).
inline constexpr std::array<LasPointFormatLayout, 11> kLasPointFormats{{
    {20, std::nullopt, 0},
    {28, std::nullopt, 0},
    {26, 20, 2},
    {34, 28, 2},
    {57, std::nullopt, 3},
    {63, 28, 3},
    {30, std::nullopt, 4},
    {36, 30, 4},
    {38, 30, 4},
    {59, std::nullopt, 4},
    {67, 30, 4},
}};

/// The public header block of a LAS file (1.0-1.4), validated against the file's size.
struct LasHeader {
    int versionMinor = 0;
    std::size_t headerSize = 0;
    std::size_t pointDataOffset = 0;
    int pointFormat = 0;  // 0-10, without laszip's compression bits
    std::size_t recordLength = 0;
    std::uint64_t pointCount = 0;
    glm::dvec3 scale{1.0};
    glm::dvec3 offset{0.0};
    Bounds declaredBounds;
    std::uint64_t evlrOffset = 0;  // LAS 1.4: where the extended VLRs start
    std::uint32_t evlrCount = 0;
    std::optional<std::span<const std::byte>> laszipRecord;  // LAZ and COPC files
};

/// Parses and checks the header of a LAS file of `fileSize` bytes. `head` holds the file's first
/// bytes: at least up to the point data offset (the header and its VLRs), or all of them when
/// the file is shorter than a LAS 1.4 header. Format variants worth knowing about become
/// warnings in `context`; throws subscan::Error for what cannot be read. The returned spans
/// point into `head`.
LasHeader parseLasHeader(std::span<const std::byte> head, std::uint64_t fileSize,
                         ReadContext& context);

/// The payload of the first VLR (between the header and the point data) with this user id and
/// record id. The VLR area belongs to other readers too: a malformed one merely ends the search.
std::optional<std::span<const std::byte>> findLasVlr(std::span<const std::byte> head,
                                                     const LasHeader& header, std::string_view user,
                                                     std::uint16_t recordId);

}  // namespace subscan
