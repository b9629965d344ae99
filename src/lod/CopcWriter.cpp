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
#include "io/Las14Writer.h"
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
    Las14Summary summary;
    summary.add(records, source_.format.recordLength());

    std::lock_guard lock(mutex_);
    idleEncoders_.push_back(std::move(encoder));
    nodes_.push_back({key, {end_, chunk.size(), pointCount}});
    append(chunk);
    summary_.add(summary);
}

std::vector<std::byte> CopcWriter::prefix(std::uint64_t chunkTableOffset,
                                          std::uint64_t hierarchyOffset,
                                          std::uint64_t hierarchySize) const {
    const bool any = summary_.points > 0;
    std::vector<LasVlr> vlrs{
        textVlr(kCopcUserId, kCopcInfoRecordId, "COPC info",
                copcInfoPayload(cube_, hierarchyOffset, hierarchySize,
                                any ? summary_.gpsTimeMin : 0.0, any ? summary_.gpsTimeMax : 0.0))};
    for (LasVlr& vlr : las14Vlrs(source_)) {
        vlrs.push_back(std::move(vlr));
    }
    const laz::LazLayout layout =
        laz::layeredLazLayout(source_.format.pointFormat, source_.format.recordLength());
    const std::uint64_t firstEvlr =
        hierarchyOffset == 0 ? 0 : hierarchyOffset - las::kEvlrHeaderSize;
    return encodeLazPrefix(las14Header(source_, summary_, "subscan index"), vlrs, layout,
                           chunkTableOffset, firstEvlr, hierarchyOffset == 0 ? 0 : 1);
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

CopcFile writeCopc(PointRecordSource& source, const std::filesystem::path& output,
                   const IndexSettings& settings) {
    const PointRecordSourceInfo& info = source.info();
    CopcWriter writer(output, info, octreeCubeFor(info.min, info.max));
    CopcFile file;
    file.summary = buildOctree(source, writer, settings);
    if (settings.cancelled != nullptr && settings.cancelled->load()) {
        throw Error("interrupted; no output was written");
    }
    file.bytes = writer.finish();
    return file;
}

}  // namespace subscan::lod
