#include "io/laz/Copc.h"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"

namespace subscan::laz {

namespace {
constexpr std::size_t kInfoSize = 160;
constexpr std::size_t kEntrySize = 32;
}  // namespace

CopcInfo parseCopcInfo(std::span<const std::byte> payload) {
    if (payload.size() < kInfoSize) {
        throw Error(fmt::format("the COPC info VLR has {} bytes, fewer than its {}", payload.size(),
                                kInfoSize));
    }
    const std::byte* p = payload.data();
    CopcInfo info;
    info.center = {loadLittleEndian<double>(p), loadLittleEndian<double>(p + 8),
                   loadLittleEndian<double>(p + 16)};
    info.halfSize = loadLittleEndian<double>(p + 24);
    info.rootSpacing = loadLittleEndian<double>(p + 32);
    info.rootHierarchyOffset = loadLittleEndian<std::uint64_t>(p + 40);
    info.rootHierarchySize = loadLittleEndian<std::uint64_t>(p + 48);
    return info;
}

std::vector<CopcNode> readCopcHierarchy(std::span<const std::byte> file, const CopcInfo& info) {
    struct Page {
        std::uint64_t offset, size;
    };
    std::vector<Page> pending{{info.rootHierarchyOffset, info.rootHierarchySize}};
    std::set<std::uint64_t> visited;  // a page listed twice (or a cycle) is read once
    std::vector<CopcNode> nodes;
    while (!pending.empty()) {
        const Page page = pending.back();
        pending.pop_back();
        if (!visited.insert(page.offset).second) {
            continue;
        }
        if (page.offset > file.size() || page.size > file.size() - page.offset) {
            throw Error(fmt::format(
                "the COPC hierarchy page at byte {} ({} bytes) lies beyond the end of the file "
                "({} bytes; truncated?)",
                page.offset, page.size, file.size()));
        }
        if (page.size % kEntrySize != 0) {
            throw Error(fmt::format(
                "the COPC hierarchy page at byte {} has {} bytes, not a multiple of its "
                "{}-byte entries",
                page.offset, page.size, kEntrySize));
        }
        for (std::uint64_t at = page.offset; at < page.offset + page.size; at += kEntrySize) {
            const std::byte* entry = file.data() + at;
            const VoxelKey key{loadLittleEndian<std::int32_t>(entry),
                               loadLittleEndian<std::int32_t>(entry + 4),
                               loadLittleEndian<std::int32_t>(entry + 8),
                               loadLittleEndian<std::int32_t>(entry + 12)};
            const auto offset = loadLittleEndian<std::uint64_t>(entry + 16);
            const auto byteSize = loadLittleEndian<std::int32_t>(entry + 24);
            const auto pointCount = loadLittleEndian<std::int32_t>(entry + 28);
            if (byteSize < 0 || pointCount < -1) {
                throw Error(fmt::format(
                    "the COPC hierarchy entry of node {}-{}-{}-{} has byte size {} and point "
                    "count {}",
                    key.level, key.x, key.y, key.z, byteSize, pointCount));
            }
            if (pointCount == -1) {
                pending.push_back({offset, static_cast<std::uint64_t>(byteSize)});
            } else if (pointCount > 0) {
                if (offset > file.size() ||
                    static_cast<std::uint64_t>(byteSize) > file.size() - offset) {
                    throw Error(fmt::format(
                        "the COPC node {}-{}-{}-{} lies beyond the end of the file (byte {} + "
                        "{}; truncated?)",
                        key.level, key.x, key.y, key.z, offset, byteSize));
                }
                nodes.push_back({key,
                                 {offset, static_cast<std::uint64_t>(byteSize),
                                  static_cast<std::uint64_t>(pointCount)}});
            }
        }
    }
    std::sort(nodes.begin(), nodes.end(),
              [](const CopcNode& a, const CopcNode& b) { return a.chunk.offset < b.chunk.offset; });
    return nodes;
}

int copcLevels(std::span<const CopcNode> nodes) {
    int deepest = -1;
    for (const CopcNode& node : nodes) {
        deepest = std::max(deepest, node.key.level);
    }
    return deepest + 1;
}

}  // namespace subscan::laz
