#include "io/LazWriter.h"

#include <algorithm>
#include <limits>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/WriterSupport.h"
#include "io/laz/LazEncoder.h"

namespace subscan {

namespace {

constexpr std::string_view kLaszipDescription = "subscan LAZ encoder";
/// laszip marks compressed point data with bit 7 of the point format byte.
constexpr std::byte kCompressedBit{0x80};

template <class T>
void setField(std::vector<std::byte>& bytes, std::size_t offset, T value) {
    storeLittleEndian(bytes.data() + offset, value);
}

void appendPaddedText(std::vector<std::byte>& out, std::string_view text, std::size_t size,
                      const char* what) {
    if (text.size() > size) {
        throw Error(fmt::format("the {} \"{}\" is longer than {} bytes", what, text, size));
    }
    for (const char c : text) {
        out.push_back(static_cast<std::byte>(c));
    }
    out.resize(out.size() + size - text.size(), std::byte{0});
}

}  // namespace

void appendLasVlr(std::vector<std::byte>& out, const LasVlr& vlr, bool extended) {
    appendLittleEndian(out, std::uint16_t{0});  // reserved
    appendPaddedText(out, vlr.userId, las::kVlrUserIdSize, "VLR user id");
    appendLittleEndian(out, vlr.recordId);
    if (extended) {
        appendLittleEndian(out, static_cast<std::uint64_t>(vlr.payload.size()));
    } else {
        if (vlr.payload.size() > std::numeric_limits<std::uint16_t>::max()) {
            throw Error(fmt::format(
                "the VLR \"{}\" {} has {} bytes, more than a VLR holds (65535; an EVLR holds more)",
                vlr.userId, vlr.recordId, vlr.payload.size()));
        }
        appendLittleEndian(out, static_cast<std::uint16_t>(vlr.payload.size()));
    }
    appendPaddedText(out, vlr.description, las::kVlrDescriptionSize, "VLR description");
    out.insert(out.end(), vlr.payload.begin(), vlr.payload.end());
}

namespace {

/// Checks that the header describes `contents`' records and returns their layout.
laz::LazLayout checkedLayout(const LazFileContents& contents) {
    const std::vector<std::byte>& header = contents.header;
    if (header.size() != las::kHeaderSize14 ||
        std::string_view(reinterpret_cast<const char*>(header.data()), 4) != "LASF") {
        throw Error(fmt::format("a LAZ file needs a {}-byte LAS 1.4 header; this one has {} bytes",
                                las::kHeaderSize14, header.size()));
    }
    const auto major = static_cast<int>(header[las::header_field::kVersionMajor]);
    const auto minor = static_cast<int>(header[las::header_field::kVersionMinor]);
    if (major != 1 || minor != 4) {
        throw Error(
            fmt::format("the header says LAS {}.{}; the LAZ writer writes LAS 1.4", major, minor));
    }
    // Bits 6 and 7 of the format byte are compression marks, set below.
    const int pointFormat = static_cast<int>(header[las::header_field::kPointFormat]) & 0x3F;
    const auto recordLength =
        loadLittleEndian<std::uint16_t>(header.data() + las::header_field::kRecordLength);
    const laz::LazLayout layout = laz::layeredLazLayout(pointFormat, recordLength);
    const auto pointCount =
        loadLittleEndian<std::uint64_t>(header.data() + las::header_field::kPointCount64);
    if (contents.records.size() % recordLength != 0 ||
        contents.records.size() / recordLength != pointCount) {
        throw Error(
            fmt::format("the header declares {} points of {} bytes, but the records have {} bytes",
                        pointCount, recordLength, contents.records.size()));
    }
    std::uint64_t chunked = 0;
    for (const std::uint64_t count : contents.chunkPointCounts) {
        if (count == 0) {
            throw Error(
                "a LAZ chunk of 0 points cannot be written (each chunk stores its first "
                "point raw)");
        }
        chunked += count;
    }
    if (chunked != pointCount) {
        throw Error(fmt::format("the chunks hold {} points in all, but there are {} records",
                                chunked, pointCount));
    }
    return layout;
}

}  // namespace

std::vector<std::byte> encodeLazPrefix(std::span<const std::byte> header,
                                       std::span<const LasVlr> vlrs, const laz::LazLayout& layout,
                                       std::uint64_t chunkTableOffset,
                                       std::uint64_t firstExtendedVlrOffset,
                                       std::uint32_t extendedVlrCount) {
    std::vector<std::byte> file(header.begin(), header.end());
    for (const LasVlr& vlr : vlrs) {
        appendLasVlr(file, vlr, false);
    }
    appendLasVlr(file,
                 {std::string(las::kLaszipUserId), las::kLaszipRecordId,
                  std::string(kLaszipDescription), laz::laszipRecordPayload(layout)},
                 false);
    const std::size_t pointDataOffset = file.size();
    if (pointDataOffset > std::numeric_limits<std::uint32_t>::max()) {
        throw Error("the VLRs end beyond 4 GiB, where the header's point data offset cannot point");
    }
    appendLittleEndian(file, static_cast<std::int64_t>(chunkTableOffset));

    setField(file, las::header_field::kHeaderSize, static_cast<std::uint16_t>(las::kHeaderSize14));
    setField(file, las::header_field::kPointDataOffset,
             static_cast<std::uint32_t>(pointDataOffset));
    setField(file, las::header_field::kVlrCount, static_cast<std::uint32_t>(vlrs.size() + 1));
    // The format with bit 7 set and bit 6 (which some writers also set) clear.
    file[las::header_field::kPointFormat] =
        (file[las::header_field::kPointFormat] & std::byte{0x3F}) | kCompressedBit;
    // Formats 6-10 count points in the 64-bit fields only.
    setField(file, las::header_field::kLegacyPointCount, std::uint32_t{0});
    std::fill_n(file.begin() + las::header_field::kLegacyReturnCounts, 5 * 4, std::byte{0});
    setField(file, las::header_field::kFirstEvlrOffset,
             extendedVlrCount > 0 ? firstExtendedVlrOffset : std::uint64_t{0});
    setField(file, las::header_field::kEvlrCount, extendedVlrCount);
    return file;
}

std::vector<std::byte> encodeLazFile(const LazFileContents& contents, LazFileLayout* layout) {
    const laz::LazLayout lazLayout = checkedLayout(contents);
    // The prefix's size does not depend on the offsets it records: made once to learn where
    // the chunks start, and again at the end with the offsets.
    const std::size_t prefixSize =
        encodeLazPrefix(contents.header, contents.vlrs, lazLayout, 0, 0, 0).size();
    std::vector<std::byte> file(prefixSize);

    LazFileLayout placed;
    laz::ChunkEncoder encoder(lazLayout);
    std::size_t firstRecord = 0;
    for (const std::uint64_t count : contents.chunkPointCounts) {
        const std::size_t bytes = count * lazLayout.recordLength;
        const std::vector<std::byte> chunk =
            encoder.encode(contents.records.subspan(firstRecord, bytes));
        placed.chunks.push_back({file.size(), chunk.size(), count});
        file.insert(file.end(), chunk.begin(), chunk.end());
        firstRecord += bytes;
    }
    placed.chunkTableOffset = file.size();
    const std::vector<std::byte> table = laz::encodeChunkTable(placed.chunks, true);
    file.insert(file.end(), table.begin(), table.end());
    placed.firstExtendedVlrOffset = file.size();
    for (const LasVlr& vlr : contents.extendedVlrs) {
        appendLasVlr(file, vlr, true);
    }
    const std::vector<std::byte> prefix = encodeLazPrefix(
        contents.header, contents.vlrs, lazLayout, placed.chunkTableOffset,
        placed.firstExtendedVlrOffset, static_cast<std::uint32_t>(contents.extendedVlrs.size()));
    std::copy(prefix.begin(), prefix.end(), file.begin());
    if (layout) {
        *layout = std::move(placed);
    }
    return file;
}

LazFileLayout writeLaz(const std::filesystem::path& path, const LazFileContents& contents) {
    LazFileLayout layout;
    std::vector<std::byte> bytes;
    try {
        bytes = encodeLazFile(contents, &layout);
    } catch (const Error& error) {
        throw Error(fmt::format("{}: cannot write it as LAZ: {}", path.string(), error.what()));
    }
    writeFileAtomically(
        path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    return layout;
}

}  // namespace subscan
