#include "io/Las14Writer.h"

#include <algorithm>
#include <cstring>
#include <ctime>
#include <string>

#include <fmt/format.h>
#include <glm/common.hpp>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/WriterSupport.h"

namespace subscan {

namespace {

/// Format 6-8 records: X, Y, Z int32 at 0; the return number in the low 4 bits of byte 14;
/// GPS time, a double, at 22.
constexpr std::size_t kReturnsByte = 14;
constexpr std::size_t kGpsTimeOffset = 22;
/// Global encoding bit 4: the coordinate system is WKT, as point formats 6-10 require (R15,
/// "Coordinate Reference System VLRs"), with a WKT VLR or none: PDAL and QGIS refuse formats
/// 6-10 without the bit.
constexpr std::uint16_t kWktGlobalEncoding = 1u << 4;
constexpr std::size_t kLazChunkPoints = 50'000;

}  // namespace

void Las14Summary::add(std::span<const std::byte> records, std::size_t length) {
    for (std::size_t at = 0; at + length <= records.size(); at += length) {
        const std::byte* record = records.data() + at;
        glm::ivec3 stored;
        std::memcpy(&stored, record, sizeof stored);
        storedMin = glm::min(storedMin, stored);
        storedMax = glm::max(storedMax, stored);
        const double gpsTime = loadLittleEndian<double>(record + kGpsTimeOffset);
        gpsTimeMin = std::min(gpsTimeMin, gpsTime);
        gpsTimeMax = std::max(gpsTimeMax, gpsTime);
        const int returnNumber = static_cast<int>(record[kReturnsByte]) & 0x0F;
        if (returnNumber >= 1) {
            ++pointsByReturn[returnNumber - 1];
        }
        ++points;
    }
}

void Las14Summary::add(const Las14Summary& other) {
    points += other.points;
    for (std::size_t r = 0; r < pointsByReturn.size(); ++r) {
        pointsByReturn[r] += other.pointsByReturn[r];
    }
    storedMin = glm::min(storedMin, other.storedMin);
    storedMax = glm::max(storedMax, other.storedMax);
    gpsTimeMin = std::min(gpsTimeMin, other.gpsTimeMin);
    gpsTimeMax = std::max(gpsTimeMax, other.gpsTimeMax);
}

std::vector<std::byte> las14Header(const PointRecordSourceInfo& source, const Las14Summary& summary,
                                   std::string_view software) {
    std::vector<std::byte> header(las::kHeaderSize14, std::byte{0});
    std::memcpy(header.data(), "LASF", 4);
    storeLittleEndian(header.data() + las::header_field::kFileSourceId, source.fileSourceId);
    storeLittleEndian(header.data() + las::header_field::kGlobalEncoding,
                      static_cast<std::uint16_t>(
                          kWktGlobalEncoding |
                          (source.standardGpsTime.value_or(false) ? las::kStandardGpsTime : 0)));
    header[las::header_field::kVersionMajor] = std::byte{1};
    header[las::header_field::kVersionMinor] = std::byte{4};
    std::memcpy(header.data() + las::header_field::kSystemIdentifier, "subscan", 7);
    std::memcpy(header.data() + las::header_field::kGeneratingSoftware, software.data(),
                std::min<std::size_t>(software.size(), 31));
    const std::time_t now = std::time(nullptr);
    std::tm date{};
    ::gmtime_r(&now, &date);
    storeLittleEndian(header.data() + las::header_field::kCreationDay,
                      static_cast<std::uint16_t>(date.tm_yday + 1));
    storeLittleEndian(header.data() + las::header_field::kCreationYear,
                      static_cast<std::uint16_t>(date.tm_year + 1900));
    storeLittleEndian(header.data() + las::header_field::kHeaderSize,
                      static_cast<std::uint16_t>(las::kHeaderSize14));
    header[las::header_field::kPointFormat] = static_cast<std::byte>(source.format.pointFormat);
    storeLittleEndian(header.data() + las::header_field::kRecordLength,
                      static_cast<std::uint16_t>(source.format.recordLength()));
    const Quantization& q = source.quantization;
    const bool any = summary.points > 0;
    for (int axis = 0; axis < 3; ++axis) {
        storeLittleEndian(header.data() + las::header_field::kScale + 8 * axis, q.scale[axis]);
        storeLittleEndian(header.data() + las::header_field::kOffset + 8 * axis, q.offset[axis]);
        storeLittleEndian(header.data() + las::header_field::kBounds + 16 * axis,
                          any ? summary.storedMax[axis] * q.scale[axis] + q.offset[axis] : 0.0);
        storeLittleEndian(header.data() + las::header_field::kBounds + 16 * axis + 8,
                          any ? summary.storedMin[axis] * q.scale[axis] + q.offset[axis] : 0.0);
    }
    storeLittleEndian(header.data() + las::header_field::kPointCount64, summary.points);
    for (std::size_t r = 0; r < summary.pointsByReturn.size(); ++r) {
        storeLittleEndian(header.data() + las::header_field::kReturnCounts64 + 8 * r,
                          summary.pointsByReturn[r]);
    }
    return header;
}

std::vector<LasVlr> las14Vlrs(const PointRecordSourceInfo& source) {
    std::vector<LasVlr> vlrs;
    if (!source.wkt.empty()) {
        std::vector<std::byte> wkt(source.wkt.size() + 1, std::byte{0});  // NUL-terminated
        std::memcpy(wkt.data(), source.wkt.data(), source.wkt.size());
        vlrs.push_back({"LASF_Projection", 2112, "OGC WKT", std::move(wkt)});
    }
    if (!source.format.extraBytesDescriptors.empty()) {
        vlrs.push_back({"LASF_Spec", 4, "Extra bytes", source.format.extraBytesDescriptors});
    }
    return vlrs;
}

void writeLas14(const std::filesystem::path& path, const PointRecordSourceInfo& source,
                std::span<const std::byte> records) {
    Las14Summary summary;
    summary.add(records, source.format.recordLength());
    std::vector<std::byte> file = las14Header(source, summary, "subscan convert");
    const std::vector<LasVlr> vlrs = las14Vlrs(source);
    for (const LasVlr& vlr : vlrs) {
        appendLasVlr(file, vlr, false);
    }
    storeLittleEndian(file.data() + las::header_field::kPointDataOffset,
                      static_cast<std::uint32_t>(file.size()));
    storeLittleEndian(file.data() + las::header_field::kVlrCount,
                      static_cast<std::uint32_t>(vlrs.size()));
    file.insert(file.end(), records.begin(), records.end());
    writeFileAtomically(path,
                        std::string_view(reinterpret_cast<const char*>(file.data()), file.size()));
}

void writeLaz14(const std::filesystem::path& path, const PointRecordSourceInfo& source,
                std::span<const std::byte> records) {
    Las14Summary summary;
    const std::size_t length = source.format.recordLength();
    summary.add(records, length);
    LazFileContents contents;
    contents.header = las14Header(source, summary, "subscan convert");
    contents.vlrs = las14Vlrs(source);
    contents.records = records;
    for (std::uint64_t left = summary.points; left > 0;) {
        const std::uint64_t chunk = std::min<std::uint64_t>(left, kLazChunkPoints);
        contents.chunkPointCounts.push_back(chunk);
        left -= chunk;
    }
    writeLaz(path, contents);
}

}  // namespace subscan
