#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "io/laz/LazDecoder.h"

// COPC 1.0 (copc.io): a LAZ 1.4 file (point formats 6-8, variable chunks) whose chunks are the
// nodes of an octree. The "copc" info VLR gives the root cube and the first hierarchy page; the
// pages (in an EVLR) list every node by voxel key with its chunk's offset, size and point count,
// or point to further pages. Loading reads every node for now; a level-of-detail renderer reads
// the nodes it needs through the same node list.
namespace subscan::laz {

struct CopcInfo {
    glm::dvec3 center{0.0};
    double halfSize = 0.0;
    double rootSpacing = 0.0;  // point spacing at level 0
    std::uint64_t rootHierarchyOffset = 0;
    std::uint64_t rootHierarchySize = 0;
};

struct VoxelKey {
    std::int32_t level = 0, x = 0, y = 0, z = 0;
};

struct CopcNode {
    VoxelKey key;
    Chunk chunk;  // where the node's points lie; pointCount > 0
};

/// Parses the payload of the "copc" info VLR (record 1, 160 bytes).
CopcInfo parseCopcInfo(std::span<const std::byte> payload);

/// Walks every hierarchy page from the root and returns the nodes that hold points, in file
/// order. Checks pages and chunks against the file; each page is read once.
std::vector<CopcNode> readCopcHierarchy(std::span<const std::byte> file, const CopcInfo& info);

/// Levels (deepest level + 1) of the nodes.
int copcLevels(std::span<const CopcNode> nodes);

}  // namespace subscan::laz
