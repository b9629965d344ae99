#include "io/LasReader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LasHeader.h"
#include "io/laz/Copc.h"
#include "io/laz/LazDecoder.h"

namespace subscan {

namespace {

// The header and VLR layout (LasFormat.h); this file is compiled on its own, not in a batch.
using namespace las;

constexpr std::string_view kSignature = "LASF";
constexpr int kLatestMinorVersion = 4;
constexpr std::string_view kCopcUserId = "copc";
constexpr std::uint16_t kCopcInfoRecordId = 1;

constexpr std::size_t kIntensityOffset = 12;  // in every point format

/// Where the class code sits (LAS 1.4 R15, tables 7 and 13): formats 0-5 keep it in the low 5
/// bits of byte 15, the upper 3 being the synthetic, key-point and withheld flags; formats
/// 6-10 moved those flags into byte 15 and give the code all 8 bits of byte 16.
struct ClassificationField {
    std::size_t offset;
    std::uint8_t mask;
};
constexpr ClassificationField kLegacyClassification{15, 0x1F};
constexpr ClassificationField kExtendedClassification{16, 0xFF};
constexpr int kFirstExtendedFormat = 6;

ClassificationField classificationField(int pointFormat) {
    return pointFormat < kFirstExtendedFormat ? kLegacyClassification : kExtendedClassification;
}

template <class T>
T loadField(std::span<const std::byte> file, std::size_t offset) {
    return loadLittleEndian<T>(file.data() + offset);
}

glm::dvec3 loadDoubleTriple(std::span<const std::byte> file, std::size_t offset) {
    return {loadField<double>(file, offset), loadField<double>(file, offset + 8),
            loadField<double>(file, offset + 16)};
}

std::size_t requiredHeaderSize(int versionMinor) {
    if (versionMinor <= 2) {
        return kHeaderSizeUpTo12;
    }
    return versionMinor == 3 ? kHeaderSize13 : kHeaderSize14;
}

}  // namespace

std::optional<std::span<const std::byte>> findLasVlr(std::span<const std::byte> head,
                                                     const LasHeader& header, std::string_view user,
                                                     std::uint16_t recordId) {
    const std::uint32_t vlrCount = loadField<std::uint32_t>(head, header_field::kVlrCount);
    std::size_t position = header.headerSize;
    for (std::uint32_t i = 0; i < vlrCount; ++i) {
        if (header.pointDataOffset - position < kVlrHeaderSize) {
            return std::nullopt;
        }
        const std::byte* record = head.data() + position;
        const std::string_view userId(reinterpret_cast<const char*>(record + kVlrUserIdOffset),
                                      kVlrUserIdSize);
        const std::size_t payload = loadLittleEndian<std::uint16_t>(record + kVlrLengthOffset);
        if (header.pointDataOffset - position - kVlrHeaderSize < payload) {
            return std::nullopt;
        }
        if (userId.substr(0, userId.find('\0')) == user &&
            loadLittleEndian<std::uint16_t>(record + kVlrRecordIdOffset) == recordId) {
            return head.subspan(position + kVlrHeaderSize, payload);
        }
        position += kVlrHeaderSize + payload;
    }
    return std::nullopt;
}

namespace {

void checkScaleAndOffset(const LasHeader& header) {
    for (int axis = 0; axis < 3; ++axis) {
        const char name = "xyz"[axis];
        const double scale = header.scale[axis];
        if (!std::isfinite(scale) || scale == 0.0) {
            throw Error(
                fmt::format("the LAS {} scale factor is {}; it must be a finite, non-zero "
                            "number",
                            name, scale));
        }
        if (!std::isfinite(header.offset[axis])) {
            throw Error(fmt::format("the LAS {} offset is {}; it must be a finite number", name,
                                    header.offset[axis]));
        }
    }
}

}  // namespace

LasHeader parseLasHeader(std::span<const std::byte> head, std::uint64_t fileSize,
                         ReadContext& context) {
    if (head.size() < kSignature.size() ||
        std::memcmp(head.data(), kSignature.data(), kSignature.size()) != 0) {
        throw Error("it does not start with the LAS signature 'LASF'");
    }
    if (fileSize < kHeaderSizeUpTo12) {
        throw Error(
            fmt::format("the file has only {} bytes, fewer than the {} bytes of the smallest "
                        "LAS header (file truncated?)",
                        fileSize, kHeaderSizeUpTo12));
    }
    const auto formatByte = loadField<std::uint8_t>(head, header_field::kPointFormat);
    LasHeader header;
    const int major = loadField<std::uint8_t>(head, header_field::kVersionMajor);
    header.versionMinor = loadField<std::uint8_t>(head, header_field::kVersionMinor);
    if (major != 1 || header.versionMinor > kLatestMinorVersion) {
        throw Error(fmt::format("LAS version {}.{} is not supported (supported: 1.0 to 1.{})",
                                major, header.versionMinor, kLatestMinorVersion));
    }
    header.headerSize = loadField<std::uint16_t>(head, header_field::kHeaderSize);
    const std::size_t required = requiredHeaderSize(header.versionMinor);
    if (header.headerSize < required) {
        throw Error(
            fmt::format("the LAS 1.{} header declares a size of {} bytes, less than the {} "
                        "bytes that version needs",
                        header.versionMinor, header.headerSize, required));
    }
    if (header.headerSize > fileSize) {
        throw Error(
            fmt::format("the file has only {} bytes, fewer than its {}-byte LAS header "
                        "(file truncated?)",
                        fileSize, header.headerSize));
    }
    header.pointDataOffset = loadField<std::uint32_t>(head, header_field::kPointDataOffset);
    if (header.pointDataOffset < header.headerSize) {
        throw Error(fmt::format("the LAS point data offset {} lies inside the {}-byte header",
                                header.pointDataOffset, header.headerSize));
    }
    if (header.pointDataOffset > fileSize) {
        throw Error(
            fmt::format("the LAS point data offset {} lies beyond the end of the file "
                        "({} bytes; file truncated?)",
                        header.pointDataOffset, fileSize));
    }
    if (head.size() < header.pointDataOffset) {
        throw std::logic_error("parseLasHeader needs the file's bytes up to its point data");
    }
    header.laszipRecord = findLasVlr(head, header, kLaszipUserId, kLaszipRecordId);
    if ((formatByte & kCompressionBits) != 0 && !header.laszipRecord) {
        throw Error(fmt::format(
            "the LAS point format byte {} marks compressed (LAZ) points, but the file has no "
            "laszip VLR describing them",
            formatByte));
    }
    header.pointFormat = formatByte & ~kCompressionBits;
    if (header.pointFormat >= static_cast<int>(kLasPointFormats.size())) {
        throw Error(fmt::format("the LAS point data format {} is unknown (supported: 0 to {})",
                                header.pointFormat, kLasPointFormats.size() - 1));
    }
    const LasPointFormatLayout& layout = kLasPointFormats[header.pointFormat];
    if (layout.firstMinorVersion > header.versionMinor) {
        context.warnings.push_back(fmt::format(
            "point format {} is not defined before LAS 1.{}, but the file says LAS 1.{}; read "
            "as LAS 1.{} defines it",
            header.pointFormat, layout.firstMinorVersion, header.versionMinor,
            layout.firstMinorVersion));
    }
    header.recordLength = loadField<std::uint16_t>(head, header_field::kRecordLength);
    if (header.recordLength < layout.recordSize) {
        throw Error(
            fmt::format("the LAS point record length {} is shorter than the {} bytes "
                        "point format {} needs",
                        header.recordLength, layout.recordSize, header.pointFormat));
    }

    const std::uint32_t legacyCount =
        loadField<std::uint32_t>(head, header_field::kLegacyPointCount);
    header.pointCount = legacyCount;
    if (header.versionMinor >= 4) {
        // 1.4 writers leave the legacy count 0 when it cannot hold the count (formats 6-10 or
        // more than 2^32 points); older writers that ignore the new field leave that one 0.
        const auto count64 = loadField<std::uint64_t>(head, header_field::kPointCount64);
        if (count64 != 0) {
            if (legacyCount != 0 && legacyCount != count64) {
                context.warnings.push_back(fmt::format(
                    "the LAS header's legacy point count {} disagrees with its 64-bit count {}; "
                    "using the 64-bit count",
                    legacyCount, count64));
            }
            header.pointCount = count64;
        }
    }

    header.scale = loadDoubleTriple(head, header_field::kScale);
    header.offset = loadDoubleTriple(head, header_field::kOffset);
    checkScaleAndOffset(header);
    const std::size_t bounds = header_field::kBounds;
    header.declaredBounds.max = {loadField<double>(head, bounds),
                                 loadField<double>(head, bounds + 16),
                                 loadField<double>(head, bounds + 32)};
    header.declaredBounds.min = {loadField<double>(head, bounds + 8),
                                 loadField<double>(head, bounds + 24),
                                 loadField<double>(head, bounds + 40)};
    if (header.versionMinor >= 4) {
        header.evlrOffset = loadField<std::uint64_t>(head, header_field::kFirstEvlrOffset);
        header.evlrCount = loadField<std::uint32_t>(head, header_field::kEvlrCount);
    }
    return header;
}

namespace {

enum class ColorDepth { None, EightBit, SixteenBit };

/// LAS stores 16-bit colour, but many writers put 8-bit values in those fields. Only if no
/// channel of any point exceeds 255 are the values taken as 8-bit; real 16-bit colour nearly
/// always shows a larger value within the first points, so the scan usually stops early.
ColorDepth detectColorDepth(const std::byte* points, std::size_t count, std::size_t stride,
                            std::size_t colorOffset) {
    for (std::size_t i = 0; i < count; ++i) {
        const std::byte* rgb = points + i * stride + colorOffset;
        const auto any = static_cast<std::uint16_t>(loadLittleEndian<std::uint16_t>(rgb) |
                                                    loadLittleEndian<std::uint16_t>(rgb + 2) |
                                                    loadLittleEndian<std::uint16_t>(rgb + 4));
        if (any > 255) {
            return ColorDepth::SixteenBit;
        }
    }
    return ColorDepth::EightBit;
}

/// Whether 16-bit colour holds a value that 8-bit colour does not give back.
bool colorNeedsSixteenBits(const std::byte* points, std::size_t count, std::size_t stride,
                           std::size_t colorOffset) {
    for (std::size_t i = 0; i < count; ++i) {
        const std::byte* rgb = points + i * stride + colorOffset;
        for (std::size_t channel = 0; channel < 3; ++channel) {
            if (colorWordNeedsSixteenBits(loadLittleEndian<std::uint16_t>(rgb + 2 * channel))) {
                return true;
            }
        }
    }
    return false;
}

template <ColorDepth depth>
std::uint8_t toColorChannel(const std::byte* p) {
    const std::uint16_t value = loadLittleEndian<std::uint16_t>(p);
    if constexpr (depth == ColorDepth::SixteenBit) {
        // round(value * 255 / 65535) = round(value / 257), exactly, in integers.
        return static_cast<std::uint8_t>((value + 128u) / 257u);
    } else {
        return static_cast<std::uint8_t>(value);
    }
}

/// Where a record's normal lies among its extra bytes: PDAL's float (or double) fields
/// NormalX, NormalY and NormalZ, as `subscan index` and `convert` write them.
struct NormalFields {
    std::array<std::size_t, 3> offsets{};  // from the record's start
    bool doubles = false;
};

/// The extra bytes VLR's fields (LAS 1.4 R15, section 2.6.3: 192-byte descriptors, each field's
/// size from its data type, or from `options` for type 0), the normal's where all three are
/// there as plain floats or doubles (no scale or offset) inside the record; else nullopt.
std::optional<NormalFields> findNormalFields(std::span<const std::byte> file,
                                             const LasHeader& header) {
    constexpr std::string_view kSpecUserId = "LASF_Spec";
    constexpr std::uint16_t kExtraBytesRecordId = 4;
    constexpr std::size_t kDescriptorSize = 192;
    constexpr std::size_t kTypeSizes[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    const std::optional<std::span<const std::byte>> vlr =
        findLasVlr(file, header, kSpecUserId, kExtraBytesRecordId);
    if (!vlr) {
        return std::nullopt;
    }
    std::size_t offset = kLasPointFormats[header.pointFormat].recordSize;
    std::array<std::optional<std::size_t>, 3> found;
    std::array<std::uint8_t, 3> types{};
    for (std::size_t at = 0; at + kDescriptorSize <= vlr->size(); at += kDescriptorSize) {
        const std::byte* descriptor = vlr->data() + at;
        const auto type = std::to_integer<std::uint8_t>(descriptor[2]);
        const auto options = std::to_integer<std::uint8_t>(descriptor[3]);
        const char* name = reinterpret_cast<const char*>(descriptor + 4);
        const std::string_view field(name, strnlen(name, 32));
        if (type >= std::size(kTypeSizes)) {
            return std::nullopt;  // a deprecated array type: the later offsets are unknown
        }
        const std::size_t size = type == 0 ? options : kTypeSizes[type];
        constexpr std::uint8_t kScaleOrOffset = 0x18;  // options bits 3 and 4
        for (int axis = 0; axis < 3; ++axis) {
            if (field == std::array{"NormalX", "NormalY", "NormalZ"}[axis] &&
                (type == 9 || type == 10) && (options & kScaleOrOffset) == 0) {
                found[axis] = offset;
                types[axis] = type;
            }
        }
        offset += size;
    }
    if (!found[0] || !found[1] || !found[2] || types[0] != types[1] || types[1] != types[2]) {
        return std::nullopt;
    }
    NormalFields fields;
    fields.doubles = types[0] == 10;
    for (int axis = 0; axis < 3; ++axis) {
        fields.offsets[axis] = *found[axis];
        if (*found[axis] + (fields.doubles ? 8 : 4) > header.recordLength) {
            return std::nullopt;  // a descriptor beyond the record: not what it claims
        }
    }
    return fields;
}

/// The hot loop: the caller has checked that all `count` records lie inside the file.
template <ColorDepth depth>
void decodePoints(const std::byte* points, std::size_t count, const LasHeader& header,
                  std::size_t colorOffset, const std::optional<NormalFields>& normal,
                  PointCloudBuilder& builder, const ReadContext& context) {
    constexpr std::size_t kProgressEvery = 1 << 16;
    const std::size_t stride = header.recordLength;
    const ClassificationField classification = classificationField(header.pointFormat);
    PointRecord record;
    for (std::size_t i = 0; i < count; ++i) {
        const std::byte* p = points + i * stride;
        const glm::dvec3 stored{loadLittleEndian<std::int32_t>(p),
                                loadLittleEndian<std::int32_t>(p + 4),
                                loadLittleEndian<std::int32_t>(p + 8)};
        record.position = stored * header.scale + header.offset;
        record.intensity = loadLittleEndian<std::uint16_t>(p + kIntensityOffset);
        record.classification = static_cast<std::uint8_t>(
            std::to_integer<std::uint8_t>(p[classification.offset]) & classification.mask);
        if constexpr (depth != ColorDepth::None) {
            const std::byte* rgb = p + colorOffset;
            record.color = {toColorChannel<depth>(rgb), toColorChannel<depth>(rgb + 2),
                            toColorChannel<depth>(rgb + 4), 255};
        }
        if (normal) {
            for (int axis = 0; axis < 3; ++axis) {
                const std::byte* field = p + normal->offsets[axis];
                record.normal[axis] =
                    normal->doubles ? saturateToFloat(std::bit_cast<double>(
                                          loadLittleEndian<std::uint64_t>(field)))
                                    : std::bit_cast<float>(loadLittleEndian<std::uint32_t>(field));
            }
        }
        builder.add(record);
        if (i % kProgressEvery == 0) {
            context.reportProgress(i, count);
        }
    }
}

/// Header bounds are often stale after edits; a mismatch is worth telling, not refusing.
void warnIfBoundsDisagree(const LasHeader& header, const Bounds& decoded, ReadContext& context) {
    for (int axis = 0; axis < 3; ++axis) {
        // One scale step is what a writer's rounding can account for; the relative term covers
        // the last bits of doubles at large coordinates when the scale is extremely fine.
        const double magnitude = std::max(std::abs(decoded.min[axis]), std::abs(decoded.max[axis]));
        const double tolerance =
            std::abs(header.scale[axis]) + 4.0 * std::numeric_limits<double>::epsilon() * magnitude;
        const double declaredMin = header.declaredBounds.min[axis];
        const double declaredMax = header.declaredBounds.max[axis];
        if (!(std::abs(declaredMin - decoded.min[axis]) <= tolerance &&
              std::abs(declaredMax - decoded.max[axis]) <= tolerance)) {
            context.warnings.push_back(fmt::format(
                "the LAS header bounds ({:.12g} {:.12g} {:.12g} to {:.12g} {:.12g} {:.12g}) "
                "disagree with the points ({:.12g} {:.12g} {:.12g} to {:.12g} {:.12g} {:.12g}); "
                "the points are used",
                header.declaredBounds.min.x, header.declaredBounds.min.y,
                header.declaredBounds.min.z, header.declaredBounds.max.x,
                header.declaredBounds.max.y, header.declaredBounds.max.z, decoded.min.x,
                decoded.min.y, decoded.min.z, decoded.max.x, decoded.max.y, decoded.max.z));
            return;
        }
    }
}

/// The point records of a LAZ or COPC file, decompressed: the same bytes an uncompressed LAS
/// file of the same points holds. COPC files are read node by node through their hierarchy.
std::vector<std::byte> decompressLaz(std::span<const std::byte> file, const LasHeader& header,
                                     ReadContext& context) {
    const laz::LazLayout layout =
        laz::parseLaszipRecord(*header.laszipRecord, header.pointFormat, header.recordLength);
    const std::uint64_t compressedBytes = file.size() - header.pointDataOffset;
    if (header.pointCount > laz::kMostLazPointsPerByte * compressedBytes) {
        throw Error(fmt::format(
            "the LAS header declares {} points, far more than {} bytes of LAZ data can hold "
            "(file truncated, or the count is wrong)",
            header.pointCount, compressedBytes));
    }
    std::vector<laz::Chunk> chunks;
    const std::optional<std::span<const std::byte>> copcRecord =
        findLasVlr(file, header, kCopcUserId, kCopcInfoRecordId);
    if (copcRecord) {
        const laz::CopcInfo info = laz::parseCopcInfo(*copcRecord);
        const std::vector<laz::CopcNode> nodes = laz::readCopcHierarchy(file, info);
        std::uint64_t points = 0;
        for (const laz::CopcNode& node : nodes) {
            chunks.push_back(node.chunk);
            points += node.chunk.pointCount;
        }
        if (points != header.pointCount) {
            throw Error(fmt::format(
                "the COPC hierarchy's nodes hold {} points, but the LAS header declares {}", points,
                header.pointCount));
        }
        // Points per level: what a level-of-detail loader would read down to that level. A map,
        // not a vector by level: a damaged key's level may be any 32-bit number.
        std::map<std::int32_t, std::uint64_t> levelPoints;
        for (const laz::CopcNode& node : nodes) {
            levelPoints[node.key.level] += node.chunk.pointCount;
        }
        std::vector<std::uint64_t> perLevel;
        for (const auto& [level, levelCount] : levelPoints) {
            perLevel.push_back(levelCount);
        }
        context.formatDetail = fmt::format(
            "COPC 1.0 (LAZ, LAS 1.{}, point format {}): octree of {} levels, {} nodes, root "
            "spacing {:.6g}; points per level {}",
            header.versionMinor, header.pointFormat, laz::copcLevels(nodes), nodes.size(),
            info.rootSpacing, fmt::join(perLevel, ", "));
    } else {
        chunks = laz::readChunkTable(file, header.pointDataOffset, layout, header.pointCount);
        context.formatDetail = fmt::format(
            "LAZ (LAS 1.{}, point format {}, {} chunks, {})", header.versionMinor,
            header.pointFormat, chunks.size(),
            layout.compressor == laz::kCompressorLayeredChunked ? "layered" : "pointwise");
    }
    std::vector<std::byte> records(static_cast<std::size_t>(header.pointCount) *
                                   header.recordLength);
    laz::decodeChunks(file, layout, chunks, records, context.decodeThreads,
                      [&](std::uint64_t done) {
                          // Decoding is most of the work; the record pass after it is quick.
                          context.reportProgress(done, header.pointCount);
                      });
    return records;
}

/// The header and the point records, decompressed where the file is LAZ or COPC (then `storage`
/// holds them); every record lies inside the returned span.
std::span<const std::byte> pointRecords(std::span<const std::byte> file, const LasHeader& header,
                                        ReadContext& context, std::vector<std::byte>& storage) {
    if (header.pointCount > kMaxPoints) {
        throw Error(
            fmt::format("the LAS header declares {} points, more than the {} points "
                        "subscan can hold",
                        header.pointCount, kMaxPoints));
    }
    if (header.laszipRecord) {
        storage = decompressLaz(file, header, context);
        return storage;
    }
    // One bounds check for the whole point block, before reserving anything: a lying count
    // must neither read past the end nor allocate memory for points that are not there.
    const std::size_t available = (file.size() - header.pointDataOffset) / header.recordLength;
    if (header.pointCount > available) {
        throw Error(
            fmt::format("the LAS header declares {} points, but the point data holds "
                        "only {} (file truncated, or the count is wrong)",
                        header.pointCount, available));
    }
    return file.subspan(header.pointDataOffset,
                        static_cast<std::size_t>(header.pointCount) * header.recordLength);
}

std::string describe(const LasHeader& header) {
    return fmt::format("LAS 1.{}, point format {}", header.versionMinor, header.pointFormat);
}

}  // namespace

LasRecords readLasRecords(std::span<const std::byte> file, ReadContext& context) {
    const LasHeader header = parseLasHeader(file, file.size(), context);
    context.formatDetail = describe(header);
    std::vector<std::byte> storage;
    const std::span<const std::byte> records = pointRecords(file, header, context, storage);
    if (storage.empty()) {
        storage.assign(records.begin(), records.end());
    }
    return {header.pointFormat, header.recordLength, std::move(storage)};
}

PointCloud lasRecordsToCloud(std::span<const std::byte> head, const LasHeader& header,
                             std::span<const std::byte> records,
                             std::span<const std::byte> colorSample, const ReadContext& context,
                             std::vector<std::string>& warnings) {
    const std::byte* points = records.data();
    const std::size_t count = records.size() / header.recordLength;
    const std::optional<std::size_t> colorOffset = kLasPointFormats[header.pointFormat].colorOffset;
    const ColorDepth depth =
        colorOffset ? detectColorDepth(colorSample.data(), colorSample.size() / header.recordLength,
                                       header.recordLength, *colorOffset)
                    : ColorDepth::None;
    const std::optional<NormalFields> normal = findNormalFields(head, header);
    PointAttributes attributes;
    attributes.color = colorOffset.has_value();
    attributes.normal = normal.has_value();
    attributes.intensity = true;
    attributes.classification = true;
    PointCloudBuilder builder(attributes, count);
    if (context.keepFilePrecision) {
        builder.keepPositionResiduals();
    }
    switch (depth) {
        case ColorDepth::None:
            decodePoints<ColorDepth::None>(points, count, header, 0, normal, builder, context);
            break;
        case ColorDepth::EightBit:
            decodePoints<ColorDepth::EightBit>(points, count, header, *colorOffset, normal, builder,
                                               context);
            break;
        case ColorDepth::SixteenBit:
            decodePoints<ColorDepth::SixteenBit>(points, count, header, *colorOffset, normal,
                                                 builder, context);
            break;
    }
    context.reportProgress(count, count);
    PointCloud cloud = builder.finish(warnings);
    const glm::dvec3 step = glm::abs(header.scale);
    cloud.coordinateStep = std::min({step.x, step.y, step.z});
    cloud.colorCutTo8Bits = depth == ColorDepth::SixteenBit &&
                            colorNeedsSixteenBits(points, count, header.recordLength, *colorOffset);
    return cloud;
}

PointCloud readLas(std::span<const std::byte> file, ReadContext& context) {
    const LasHeader header = parseLasHeader(file, file.size(), context);
    context.formatDetail = describe(header);
    std::vector<std::byte> storage;
    const std::span<const std::byte> records = pointRecords(file, header, context, storage);
    // Decompression already reported the progress of a LAZ file; the record pass is quick. It
    // gets the caller's context without its progress, so that every option still reaches it
    // (keepFilePrecision was once dropped by a context made afresh).
    ReadContext silent = context;
    silent.progress = nullptr;
    PointCloud cloud = lasRecordsToCloud(file, header, records, records,
                                         header.laszipRecord ? silent : context, context.warnings);
    context.reportProgress(1, 1);
    warnIfBoundsDisagree(header, cloud.bounds, context);
    return cloud;
}

}  // namespace subscan
