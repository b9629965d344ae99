#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "io/Las14Writer.h"
#include "io/PointRecordSource.h"
#include "io/laz/Copc.h"
#include "io/laz/LazDecoder.h"
#include "lod/OctreeIndexer.h"

namespace subscan::laz {
class ChunkEncoder;
}

namespace subscan::lod {

/// Writes the octree buildOctree hands it as a COPC 1.0 file (copc.io): LAS 1.4 with the
/// source's point format (6, 7 or 8), scale, offset and extra bytes; each node one LAZ chunk
/// (layered, variable chunks), encoded on the thread that hands it over and appended to a
/// file beside the output; then the chunk table and the hierarchy (one page, in an EVLR), and
/// last the header and VLRs: the "copc" info VLR first, as COPC requires, then the laszip VLR,
/// the coordinate system's WKT and the extra bytes' descriptors where the source has them.
/// finish() renames the file to the output; a writer destroyed unfinished removes it.
class CopcWriter final : public NodeSink {
  public:
    /// Throws subscan::Error naming `output` when its folder cannot hold a new file.
    CopcWriter(const std::filesystem::path& output, const PointRecordSourceInfo& source,
               const OctreeCube& cube);
    ~CopcWriter() override;
    CopcWriter(const CopcWriter&) = delete;
    CopcWriter& operator=(const CopcWriter&) = delete;

    void writeNode(const laz::VoxelKey& key, std::span<const std::byte> records,
                   std::size_t pointCount) override;

    /// Writes the chunk table, the hierarchy and the header, flushes the file to the disk and
    /// renames it to the output. Returns the output's size in bytes.
    std::uint64_t finish();

  private:
    struct Node {
        laz::VoxelKey key;
        laz::Chunk chunk;
    };

    std::unique_ptr<laz::ChunkEncoder> takeEncoder();
    void append(std::span<const std::byte> bytes);
    std::vector<std::byte> prefix(std::uint64_t chunkTableOffset, std::uint64_t hierarchyOffset,
                                  std::uint64_t hierarchySize) const;

    std::filesystem::path output_;
    std::filesystem::path partial_;
    PointRecordSourceInfo source_;
    OctreeCube cube_;
    std::size_t prefixSize_ = 0;

    std::mutex mutex_;  // guards everything below
    std::FILE* file_ = nullptr;
    std::uint64_t end_ = 0;
    std::vector<std::unique_ptr<laz::ChunkEncoder>> idleEncoders_;
    std::vector<Node> nodes_;  // in file order
    Las14Summary summary_;
    bool finished_ = false;
};

/// What writeCopc made.
struct CopcFile {
    IndexSummary summary;
    std::uint64_t bytes = 0;
};

/// Indexes `source` into a COPC file at `output`: buildOctree into a CopcWriter of the source's
/// cube, then finish() — unless `settings.cancelled` turned true, which is then an error and
/// leaves no file.
CopcFile writeCopc(PointRecordSource& source, const std::filesystem::path& output,
                   const IndexSettings& settings);

}  // namespace subscan::lod
