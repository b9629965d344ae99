#include "lod/NodeCache.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/Error.h"

namespace subscan::lod {
namespace {

constexpr std::size_t kPointsPerNode = 1000;
constexpr std::size_t kNodes = 8;
constexpr std::size_t kBrokenNode = 5;

/// Node i holds kPointsPerNode points at x = i; node kBrokenNode cannot be read. Counts reads.
class CountingSource final : public NodeSource {
  public:
    CountingSource() {
        info_.name = "counting";
        info_.points = kNodes * kPointsPerNode;
        std::vector<StreamedNode> nodes;
        for (std::size_t i = 0; i < kNodes; ++i) {
            nodes.push_back({laz::VoxelKey{i == 0 ? 0 : 1, static_cast<std::int32_t>(i % 2),
                                           static_cast<std::int32_t>((i / 2) % 2),
                                           static_cast<std::int32_t>(i / 4)},
                             kPointsPerNode});
        }
        setNodes(std::move(nodes));
    }
    PointCloud load(std::size_t index) const override {
        ++reads[index];
        if (index == kBrokenNode) {
            throw Error("node 1-1-0-1: the tile is truncated");
        }
        PointCloud cloud;
        cloud.positions.assign(kPointsPerNode, glm::vec3(static_cast<float>(index), 0.0f, 0.0f));
        cloud.colors.assign(kPointsPerNode, Rgba8{1, 2, 3, 255});
        return cloud;
    }
    mutable std::atomic<int> reads[kNodes] = {};
};

std::size_t nodeBytes() {
    PointCloud cloud;
    cloud.positions.resize(kPointsPerNode);
    cloud.colors.resize(kPointsPerNode);
    return memoryBytes(cloud);
}

TEST(NodeCacheTest, MemoryBytesCountsEveryAttribute) {
    PointCloud cloud;
    cloud.positions.resize(10);
    cloud.colors.resize(10);
    cloud.intensities.resize(10);
    EXPECT_EQ(memoryBytes(cloud), sizeof(PointCloud) + 10 * (12 + 4 + 4));
}

TEST(NodeCacheTest, KeepsTheSourcesDescriptionAndNodes) {
    const auto source = std::make_shared<CountingSource>();
    const CachedNodeSource cache(source, 1 << 20);
    EXPECT_EQ(cache.info().name, "counting");
    ASSERT_EQ(cache.nodes().size(), source->nodes().size());
    for (std::size_t i = 0; i < kNodes; ++i) {
        EXPECT_EQ(nodeName(cache.nodes()[i].key), nodeName(source->nodes()[i].key));
        EXPECT_EQ(cache.nodes()[i].pointCount, source->nodes()[i].pointCount);
    }
}

TEST(NodeCacheTest, ANodeIsReadOnceWhileItFits) {
    const auto source = std::make_shared<CountingSource>();
    const CachedNodeSource cache(source, 1 << 20);
    for (int pass = 0; pass < 3; ++pass) {
        const PointCloud cloud = cache.load(3);
        ASSERT_EQ(cloud.size(), kPointsPerNode);
        EXPECT_EQ(cloud.positions.front().x, 3.0f);
        EXPECT_EQ(cloud.colors.back().g, 2);
    }
    EXPECT_EQ(source->reads[3], 1);
    EXPECT_EQ(cache.usage().hits, 2u);
    EXPECT_EQ(cache.usage().misses, 1u);
    EXPECT_EQ(cache.usage().bytes, nodeBytes());
}

TEST(NodeCacheTest, TheLeastRecentlyUsedNodeLeavesFirst) {
    const auto source = std::make_shared<CountingSource>();
    // Room for two nodes and a half: a third evicts one.
    const CachedNodeSource cache(source, nodeBytes() * 5 / 2);
    cache.load(0);
    cache.load(1);
    cache.load(0);  // now 1 is the least recently used
    cache.load(2);  // evicts 1
    EXPECT_EQ(cache.usage().nodes, 2u);
    EXPECT_LE(cache.usage().bytes, cache.byteBudget());
    cache.load(0);
    cache.load(2);
    EXPECT_EQ(source->reads[0], 1);
    EXPECT_EQ(source->reads[2], 1);
    cache.load(1);
    EXPECT_EQ(source->reads[1], 2);
}

TEST(NodeCacheTest, ANodeLargerThanTheBudgetIsReadEachTimeAndNotKept) {
    const auto source = std::make_shared<CountingSource>();
    const CachedNodeSource cache(source, nodeBytes() / 2);
    EXPECT_EQ(cache.load(4).size(), kPointsPerNode);
    EXPECT_EQ(cache.load(4).size(), kPointsPerNode);
    EXPECT_EQ(source->reads[4], 2);
    EXPECT_EQ(cache.usage().bytes, 0u);
}

TEST(NodeCacheTest, ANodeThatCannotBeReadIsTriedOnceAndItsSentenceKept) {
    const auto source = std::make_shared<CountingSource>();
    const CachedNodeSource cache(source, 1 << 20);
    for (int pass = 0; pass < 2; ++pass) {
        try {
            cache.load(kBrokenNode);
            ADD_FAILURE() << "the broken node loaded";
        } catch (const Error& error) {
            EXPECT_STREQ(error.what(), "node 1-1-0-1: the tile is truncated");
        }
    }
    EXPECT_EQ(source->reads[kBrokenNode], 1);
}

TEST(NodeCacheTest, ThreadsLoadingAtOnceGetTheirNodesWithinTheBudget) {
    const auto source = std::make_shared<CountingSource>();
    const CachedNodeSource cache(source, nodeBytes() * 3);
    std::atomic<int> wrong{0};
    {
        std::vector<std::jthread> threads;
        for (int t = 0; t < 4; ++t) {
            threads.emplace_back([&, t] {
                for (int i = 0; i < 400; ++i) {
                    const std::size_t node = static_cast<std::size_t>((i * 7 + t) % kNodes);
                    if (node == kBrokenNode) {
                        continue;
                    }
                    const PointCloud cloud = cache.load(node);
                    if (cloud.size() != kPointsPerNode ||
                        cloud.positions[kPointsPerNode / 2].x != static_cast<float>(node)) {
                        ++wrong;
                    }
                }
            });
        }
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_LE(cache.usage().bytes, cache.byteBudget());
    EXPECT_LE(cache.usage().nodes, 3u);
}

}  // namespace
}  // namespace subscan::lod
