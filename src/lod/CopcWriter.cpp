#include "lod/CopcWriter.h"

#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <glm/common.hpp>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasFormat.h"
#include "io/LazWriter.h"
#include "io/WriterSupport.h"
#include "io/laz/LazEncoder.h"

namespace subscan::lod {

namespace {

constexpr std::string_view kCopcUserId = "copc";
constexpr std::uint16_t kCopcInfoRecordId = 1;
constexpr std::uint16_t kCopcHierarchyRecordId = 1000;
constexpr std::size_t kCopcInfoSize = 160;
constexpr std::size_t kHierarchyEntrySize = 32;
constexpr std::string_view kProjectionUserId = "LASF_Projection";
constexpr std::uint16_t kWktRecordId = 2112;
constexpr std::string_view kSpecUserId = "LASF_Spec";
constexpr std::uint16_t kExtraBytesRecordId = 4;
/// Global encoding bit 4: the coordinate system is WKT, as point formats 6-10 require.
constexpr std::uint16_t kWktGlobalEncoding = 1u << 4;

/// Format 6-8 records: X, Y, Z int32 at 0; the return number in the low 4 bits of byte 14;
/// GPS time, a double, at 22.
constexpr std::size_t kReturnsByte = 14;
constexpr std::size_t kGpsTimeOffset = 22;

std::vector<std::byte> copcInfoPayload(const OctreeCube& cube, std::uint64_t hierarchyOffset,
                                       std::uint64_t hierarchySize, double gpsMin, double gpsMax) {
    std::vector<std::byte> payload;
    for (const double value :
         {cube.center.x, cube.center.y, cube.center.z, cube.halfSize, cube.rootSpacing}) {
        appendLittleEndian(payload, value);
    }
    appendLittleEndian(payload, hierarchyOffset);
    appendLittleEndian(payload, hierarchySize);
    appendLittleEndian(payload, gpsMin);
    appendLittleEndian(payload, gpsMax);
    payload.resize(kCopcInfoSize, std::byte{0});  // 11 reserved 64-bit words
    return payload;
}

LasVlr textVlr(std::string_view userId, std::uint16_t recordId, std::string_view description,
               std::span<const std::byte> payload) {
    return {std::string(userId), recordId, std::string(description),
            std::vector<std::byte>(payload.begin(), payload.end())};
}

}  // namespace

CopcWriter::CopcWriter(const std::filesystem::path& output, const PointRecordSourceInfo& source,
                       const OctreeCube& cube)
    : output_(output),
      partial_(output.parent_path() /
               fmt::format(".{}.partial-{}", output.filename().string(), ::getpid())),
      source_(source),
      cube_(cube) {
    file_ = std::fopen(partial_.c_str(), "wb");
    if (file_ == nullptr) {
        throw Error(fmt::format("{}: cannot create a file beside it: {}", output.string(),
                                std::strerror(errno)));
    }
    // The header and VLRs come last, when the chunk table's and hierarchy's places are known;
    // their size is known now (the values are placeholders).
    prefixSize_ = prefix(0, 0, 0).size();
    append(std::vector<std::byte>(prefixSize_, std::byte{0}));
    storedMin_ = glm::ivec3(std::numeric_limits<int>::max());
    storedMax_ = glm::ivec3(std::numeric_limits<int>::min());
    gpsTimeMin_ = std::numeric_limits<double>::infinity();
    gpsTimeMax_ = -std::numeric_limits<double>::infinity();
}

CopcWriter::~CopcWriter() {
    if (file_ != nullptr) {
        std::fclose(file_);
    }
    if (!finished_) {
        std::error_code ignored;
        std::filesystem::remove(partial_, ignored);
    }
}

std::unique_ptr<laz::ChunkEncoder> CopcWriter::takeEncoder() {
    std::lock_guard lock(mutex_);
    if (idleEncoders_.empty()) {
        return std::make_unique<laz::ChunkEncoder>(
            laz::layeredLazLayout(source_.format.pointFormat, source_.format.recordLength()));
    }
    std::unique_ptr<laz::ChunkEncoder> encoder = std::move(idleEncoders_.back());
    idleEncoders_.pop_back();
    return encoder;
}

void CopcWriter::append(std::span<const std::byte> bytes) {
    if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
        throw Error(fmt::format("{}: cannot write (is the disk full?): {}", output_.string(),
                                std::strerror(errno)));
    }
    end_ += bytes.size();
}

void CopcWriter::writeNode(const laz::VoxelKey& key, std::span<const std::byte> records,
                           std::size_t pointCount) {
    if (pointCount == 0) {
        return;
    }
    if (pointCount > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
        throw Error(fmt::format("{}: a node of {} points is more than COPC's 32-bit count holds",
                                output_.string(), pointCount));
    }
    std::unique_ptr<laz::ChunkEncoder> encoder = takeEncoder();
    const std::vector<std::byte> chunk = encoder->encode(records);

    // What the header sums up, from this node's records.
    const std::size_t length = source_.format.recordLength();
    glm::ivec3 low(std::numeric_limits<int>::max()), high(std::numeric_limits<int>::min());
    double gpsLow = std::numeric_limits<double>::infinity(), gpsHigh = -gpsLow;
    std::uint64_t byReturn[15] = {};
    for (std::size_t i = 0; i < pointCount; ++i) {
        const std::byte* record = records.data() + i * length;
        glm::ivec3 stored;
        std::memcpy(&stored, record, sizeof stored);
        low = glm::min(low, stored);
        high = glm::max(high, stored);
        const double gpsTime = loadLittleEndian<double>(record + kGpsTimeOffset);
        gpsLow = std::min(gpsLow, gpsTime);
        gpsHigh = std::max(gpsHigh, gpsTime);
        const int returnNumber = static_cast<int>(record[kReturnsByte]) & 0x0F;
        if (returnNumber >= 1) {
            ++byReturn[returnNumber - 1];
        }
    }

    std::lock_guard lock(mutex_);
    idleEncoders_.push_back(std::move(encoder));
    nodes_.push_back({key, {end_, chunk.size(), pointCount}});
    append(chunk);
    points_ += pointCount;
    for (int r = 0; r < 15; ++r) {
        pointsByReturn_[r] += byReturn[r];
    }
    storedMin_ = glm::min(storedMin_, low);
    storedMax_ = glm::max(storedMax_, high);
    gpsTimeMin_ = std::min(gpsTimeMin_, gpsLow);
    gpsTimeMax_ = std::max(gpsTimeMax_, gpsHigh);
}

std::vector<std::byte> CopcWriter::prefix(std::uint64_t chunkTableOffset,
                                          std::uint64_t hierarchyOffset,
                                          std::uint64_t hierarchySize) const {
    std::vector<std::byte> header(las::kHeaderSize14, std::byte{0});
    std::memcpy(header.data(), "LASF", 4);
    storeLittleEndian(header.data() + las::header_field::kGlobalEncoding, kWktGlobalEncoding);
    header[las::header_field::kVersionMajor] = std::byte{1};
    header[las::header_field::kVersionMinor] = std::byte{4};
    const auto copyText = [&](std::size_t offset, std::string_view text) {
        std::memcpy(header.data() + offset, text.data(), text.size());
    };
    copyText(las::header_field::kSystemIdentifier, "subscan");
    copyText(las::header_field::kGeneratingSoftware, "subscan index");
    const std::time_t now = std::time(nullptr);
    std::tm date{};
    ::gmtime_r(&now, &date);
    storeLittleEndian(header.data() + las::header_field::kCreationDay,
                      static_cast<std::uint16_t>(date.tm_yday + 1));
    storeLittleEndian(header.data() + las::header_field::kCreationYear,
                      static_cast<std::uint16_t>(date.tm_year + 1900));
    header[las::header_field::kPointFormat] = static_cast<std::byte>(source_.format.pointFormat);
    storeLittleEndian(header.data() + las::header_field::kRecordLength,
                      static_cast<std::uint16_t>(source_.format.recordLength()));
    const Quantization& q = source_.quantization;
    for (int axis = 0; axis < 3; ++axis) {
        storeLittleEndian(header.data() + las::header_field::kScale + 8 * axis, q.scale[axis]);
        storeLittleEndian(header.data() + las::header_field::kOffset + 8 * axis, q.offset[axis]);
        const bool any = points_ > 0;
        storeLittleEndian(header.data() + las::header_field::kBounds + 16 * axis,
                          any ? storedMax_[axis] * q.scale[axis] + q.offset[axis] : 0.0);
        storeLittleEndian(header.data() + las::header_field::kBounds + 16 * axis + 8,
                          any ? storedMin_[axis] * q.scale[axis] + q.offset[axis] : 0.0);
    }
    storeLittleEndian(header.data() + las::header_field::kPointCount64, points_);
    for (int r = 0; r < 15; ++r) {
        storeLittleEndian(header.data() + las::header_field::kReturnCounts64 + 8 * r,
                          pointsByReturn_[r]);
    }

    const bool anyGpsTime = points_ > 0;
    std::vector<LasVlr> vlrs{
        textVlr(kCopcUserId, kCopcInfoRecordId, "COPC info",
                copcInfoPayload(cube_, hierarchyOffset, hierarchySize,
                                anyGpsTime ? gpsTimeMin_ : 0.0, anyGpsTime ? gpsTimeMax_ : 0.0))};
    if (!source_.wkt.empty()) {
        std::vector<std::byte> wkt(source_.wkt.size() + 1, std::byte{0});  // NUL-terminated
        std::memcpy(wkt.data(), source_.wkt.data(), source_.wkt.size());
        vlrs.push_back(textVlr(kProjectionUserId, kWktRecordId, "OGC WKT", wkt));
    }
    if (!source_.format.extraBytesDescriptors.empty()) {
        vlrs.push_back(textVlr(kSpecUserId, kExtraBytesRecordId, "Extra bytes",
                               source_.format.extraBytesDescriptors));
    }
    const laz::LazLayout layout =
        laz::layeredLazLayout(source_.format.pointFormat, source_.format.recordLength());
    const std::uint64_t firstEvlr =
        hierarchyOffset == 0 ? 0 : hierarchyOffset - las::kEvlrHeaderSize;
    return encodeLazPrefix(header, vlrs, layout, chunkTableOffset, firstEvlr,
                           hierarchyOffset == 0 ? 0 : 1);
}

std::uint64_t CopcWriter::finish() {
    std::lock_guard lock(mutex_);
    const std::uint64_t chunkTableOffset = end_;
    std::vector<laz::Chunk> chunks;
    for (const Node& node : nodes_) {
        chunks.push_back(node.chunk);
    }
    append(laz::encodeChunkTable(chunks, true));

    // One hierarchy page with every node.
    std::vector<std::byte> page;
    page.reserve(nodes_.size() * kHierarchyEntrySize);
    for (const Node& node : nodes_) {
        for (const std::int32_t value : {node.key.level, node.key.x, node.key.y, node.key.z}) {
            appendLittleEndian(page, value);
        }
        appendLittleEndian(page, node.chunk.offset);
        appendLittleEndian(page, static_cast<std::int32_t>(node.chunk.byteSize));
        appendLittleEndian(page, static_cast<std::int32_t>(node.chunk.pointCount));
    }
    std::vector<std::byte> evlr;
    appendLasVlr(evlr, textVlr(kCopcUserId, kCopcHierarchyRecordId, "EPT hierarchy", page), true);
    const std::uint64_t hierarchyOffset = end_ + las::kEvlrHeaderSize;
    append(evlr);

    const std::vector<std::byte> head = prefix(chunkTableOffset, hierarchyOffset, page.size());
    if (head.size() != prefixSize_) {
        throw Error(fmt::format("{}: the header changed size while writing", output_.string()));
    }
    const bool written = std::fseek(file_, 0, SEEK_SET) == 0 &&
                         std::fwrite(head.data(), 1, head.size(), file_) == head.size() &&
                         std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!written || !closed) {
        throw Error(fmt::format("{}: cannot write (is the disk full?): {}", output_.string(),
                                std::strerror(errno)));
    }
    std::error_code error;
    std::filesystem::rename(partial_, output_, error);
    if (error) {
        throw Error(fmt::format("{}: cannot put the finished file in place: {}", output_.string(),
                                error.message()));
    }
    finished_ = true;
    return end_;
}

}  // namespace subscan::lod
