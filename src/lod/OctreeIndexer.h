#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "io/PointRecordSource.h"
#include "io/laz/Copc.h"

// The level-of-detail octree of `subscan index` (after Schütz, Ohrhallinger & Wimmer, "Fast
// Out-of-Core Octree Generation for Massive Point Clouds", 2020): every input point is stored
// exactly once, in the shallowest node that accepts it. A node of level L accepts points at
// least rootSpacing / 2^L apart from each other (Poisson-disk-like acceptance, drawn from its
// children's points), so the union of levels 0..L is an even sample of spacing rootSpacing / 2^L
// and a renderer can take its local spacing from the level (leaves keep what no level took, at
// the scan's own density). The cloud is cut into chunks, each indexed on a thread of its own;
// the levels above the chunks are built last from the chunks' top nodes. A cloud that fits a
// third of the memory budget is read once and sorted into chunks in memory; a larger one is
// read twice, out of core: a counting pass cuts chunks that fit the budget, and a distribution
// pass writes them to temporary files.
namespace subscan::lod {

/// The root cube and spacing, as the COPC info VLR records them.
struct OctreeCube {
    glm::dvec3 center{0.0};
    double halfSize = 0.0;
    double rootSpacing = 0.0;
};

/// The root node's side over its spacing: a level holds about 128 x 128 points over a surface
/// that crosses its cube, as PotreeConverter's nodes do.
inline constexpr int kRootGridCells = 128;

/// The smallest cube around `min`..`max` (file coordinates), centred on them, with the root
/// spacing of kRootGridCells. A flat or single-point cloud still gets a cube of positive size.
OctreeCube octreeCubeFor(const glm::dvec3& min, const glm::dvec3& max);

/// The key of the node at `level` whose cube holds `position` (points on or beyond the cube's
/// faces go to the nearest node inside).
laz::VoxelKey nodeKeyAt(const OctreeCube& cube, const glm::dvec3& position, int level);

struct IndexSettings {
    unsigned threads = 0;  // 0: every core
    /// Peak memory the indexer aims for: chunks are cut so that `threads` of them, with their
    /// working arrays, and the distribution buffers fit.
    std::size_t memoryBytes = std::size_t{1536} << 20;
    std::filesystem::path temporaryDirectory;  // a folder of the indexer's own is made inside
    /// A node holding more points than this is split (leaves never hold more, unless all their
    /// points share one position): about one LAZ chunk's worth, small enough for a renderer to
    /// load and upload a node within a frame.
    std::size_t maxNodePoints = 100'000;
    /// 0..1 and the phase's name; called from one thread at a time (not always the same).
    std::function<void(double fraction, std::string_view phase)> progress;
    /// Set by another thread (Ctrl-C): the indexer stops at its next step with an error.
    const std::atomic<bool>* cancelled = nullptr;
};

/// Receives each finished node's records (contiguous, the source's record format). Called from
/// several threads at once and in no particular order: implementations synchronise.
class NodeSink {
  public:
    virtual ~NodeSink() = default;
    virtual void writeNode(const laz::VoxelKey& key, std::span<const std::byte> records,
                           std::size_t pointCount) = 0;
};

struct LevelCount {
    std::uint64_t nodes = 0;
    std::uint64_t points = 0;
};

struct IndexSummary {
    std::uint64_t nodes() const {
        std::uint64_t count = 0;
        for (const LevelCount& level : levels) {
            count += level.nodes;
        }
        return count;
    }

    OctreeCube cube;
    std::vector<LevelCount> levels;  // by level
    std::uint64_t points = 0;
    std::size_t chunks = 0;       // pieces indexed one per thread at a time
    std::size_t largestNode = 0;  // points
};

/// Reads `source` (twice when it does not fit in one chunk), hands every node to `sink` and
/// removes its temporary files whether it succeeds or throws. Throws subscan::Error (an empty
/// source, a full disk, cancellation).
IndexSummary buildOctree(PointRecordSource& source, NodeSink& sink, const IndexSettings& settings);

}  // namespace subscan::lod
