// The viewer's loading of a streamed view (StreamedViewJob): partial sets of the view's first
// nodes on the way to the whole, where the budget is a GPU's; none on software rendering.
#include "app/viewer/StreamedViewJob.h"

#include <chrono>
#include <memory>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/Coloring.h"
#include "lod/NodeSelection.h"

namespace subscan::viewer {
namespace {

/// The cube [-1, 1]^3: a root of 8 points, its 8 octants of 1 point each, and below each
/// octant one node of 1 point.
class SmallOctree final : public lod::NodeSource {
  public:
    SmallOctree() {
        info_.name = "small octree";
        info_.cube = lod::OctreeCube{glm::dvec3(0.0), 1.0, 0.5};
        info_.bounds.add(glm::dvec3(-1.0));
        info_.bounds.add(glm::dvec3(1.0));
        std::vector<lod::StreamedNode> nodes{{laz::VoxelKey{0, 0, 0, 0}, 8}};
        for (int octant = 0; octant < 8; ++octant) {
            const int x = octant & 1, y = (octant >> 1) & 1, z = octant >> 2;
            nodes.push_back({laz::VoxelKey{1, x, y, z}, 1});
            nodes.push_back({laz::VoxelKey{2, 1 + x, 1 + y, 1 + z}, 1});
        }
        info_.points = 24;
        setNodes(std::move(nodes));
    }

    PointCloud load(std::size_t index) const override {
        const laz::VoxelKey key = nodes()[index].key;
        PointCloud cloud;
        const double side = 2.0 / (1 << key.level);
        for (std::uint64_t i = 0; i < nodes()[index].pointCount; ++i) {
            const glm::dvec3 inCube(0.2 + 0.6 * static_cast<double>(i & 1),
                                    0.2 + 0.6 * static_cast<double>((i >> 1) & 1),
                                    0.2 + 0.6 * static_cast<double>(i >> 2));
            const glm::dvec3 position =
                glm::dvec3(-1.0) + side * (glm::dvec3(key.x, key.y, key.z) + inCube);
            cloud.positions.emplace_back(position);
            cloud.bounds.add(position);
        }
        return cloud;
    }
};

TEST(StreamedViewJobTest, PartialSetsOnlyForAGpusBudget) {
    EXPECT_EQ(partialViewPoints(1'000'000), 0u);  // llvmpipe's default
    EXPECT_EQ(partialViewPoints(4 * kAlwaysLocalSpacingPoints - 1), 0u);
    EXPECT_EQ(partialViewPoints(4 * kAlwaysLocalSpacingPoints), kAlwaysLocalSpacingPoints);
    EXPECT_EQ(partialViewPoints(10'000'000), 2'500'000u);  // a GPU's default
}

TEST(StreamedViewJobTest, PartialSetsEndWhereTheyReachTheirPointsAndNeverAtTheWhole) {
    const SmallOctree source;
    std::vector<std::size_t> nodes(source.nodes().size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        nodes[i] = i;  // the root (8 points), then 16 nodes of 1
    }
    EXPECT_TRUE(partialViewEnds(source.nodes(), nodes, 0).empty());
    // 8 after the root, then 4 more points each: 12, 16, 20, 24 (the whole, left out).
    EXPECT_EQ(partialViewEnds(source.nodes(), nodes, 4), (std::vector<std::size_t>{1, 5, 9, 13}));
    EXPECT_TRUE(partialViewEnds(source.nodes(), nodes, 100).empty());
}

TEST(StreamedViewJobTest, TheJobOffersItsFirstNodesOnTheWayToTheWholeView) {
    const auto source =
        std::make_shared<lod::CachedNodeSource>(std::make_shared<SmallOctree>(), 1 << 20);
    const Camera camera = orbitCamera(source->info().bounds, OrbitView{}, 320, 240, 45.0);
    const std::vector<std::size_t> whole = lod::selectNodes(*source, camera, 1000);
    ASSERT_GT(whole.size(), 5u);
    const std::vector<std::size_t> ends = partialViewEnds(source->nodes(), whole, 4);
    ASSERT_GE(ends.size(), 2u);

    const std::pair coloredBy(Coloring::Height, UpAxis::Z);
    StreamedViewJob job(source, "small octree", camera, 1000, {}, coloredBy, 4);
    for (int wait = 0; wait < 10'000 && !job.finished(); ++wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_TRUE(job.finished());
    EXPECT_EQ(job.partialsPrepared(), ends.size());
    // The last partial set, not taken, waits: the first nodes of the whole, prepared.
    std::optional<PreparedScan> partial = job.takePartial();
    ASSERT_TRUE(partial);
    EXPECT_EQ(partial->nodes, std::vector<std::size_t>(whole.begin(), whole.begin() + ends.back()));
    EXPECT_EQ(partial->scan.cloud.size(), partial->scan.levelSpacing.size());
    EXPECT_GT(partial->spacing.global, 0.0);  // provisional, but usable
    EXPECT_TRUE(partial->provisional);
    EXPECT_FALSE(job.takePartial());  // taken
    std::optional<PreparedScan> result = job.take();
    ASSERT_TRUE(result);
    EXPECT_EQ(result->nodes, whole);
    EXPECT_GT(result->scan.cloud.size(), partial->scan.cloud.size());
    EXPECT_FALSE(result->provisional);
    // Each set comes coloured as the viewer asked and packed for the GPU, off its thread.
    for (const PreparedScan* prepared : {&*partial, &*result}) {
        EXPECT_EQ(prepared->coloredBy, coloredBy);
        EXPECT_EQ(prepared->shownColors,
                  pointColors(prepared->scan.cloud, coloredBy.first, coloredBy.second));
        // The nodes' levels give every point a local spacing, provisional sets too.
        ASSERT_EQ(prepared->spacing.local.size(), prepared->scan.cloud.size());
        EXPECT_EQ(prepared->packed.localSpacing.halves,
                  packLocalSpacing(prepared->spacing.local).halves);
    }

    // Without partial sets (llvmpipe's budget) none is offered. A colouring the points lack
    // (they have no RGB) is left to the viewer, which says what is missing.
    StreamedViewJob plain(source, "small octree", camera, 1000, {},
                          std::pair(Coloring::Rgb, UpAxis::Z));
    for (int wait = 0; wait < 10'000 && !plain.finished(); ++wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_TRUE(plain.finished());
    EXPECT_EQ(plain.partialsPrepared(), 0u);
    EXPECT_FALSE(plain.takePartial());
    std::optional<PreparedScan> uncoloured = plain.take();
    ASSERT_TRUE(uncoloured);
    EXPECT_FALSE(uncoloured->coloredBy);
    EXPECT_TRUE(uncoloured->shownColors.empty());
}

TEST(StreamedViewJobTest, AViewOfTheNodesShownLoadsNothingUnlessTheyWereProvisional) {
    const auto source =
        std::make_shared<lod::CachedNodeSource>(std::make_shared<SmallOctree>(), 1 << 20);
    const Camera camera = orbitCamera(source->info().bounds, OrbitView{}, 320, 240, 45.0);
    const std::vector<std::size_t> view = lod::selectNodes(*source, camera, 1000);
    const auto finish = [](StreamedViewJob& job) {
        for (int wait = 0; wait < 10'000 && !job.finished(); ++wait) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        EXPECT_TRUE(job.finished());
        return job.take();
    };
    // The viewer passes the nodes on screen, or none where they were shown provisionally (the
    // overview, a partial set): then the same nodes come again, with their spacing.
    const std::pair coloredBy(Coloring::Height, UpAxis::Z);
    StreamedViewJob same(source, "small octree", camera, 1000, view, coloredBy);
    EXPECT_FALSE(finish(same));
    StreamedViewJob again(source, "small octree", camera, 1000, {}, coloredBy);
    const std::optional<PreparedScan> prepared = finish(again);
    ASSERT_TRUE(prepared);
    EXPECT_EQ(prepared->nodes, view);
    EXPECT_FALSE(prepared->provisional);
}

}  // namespace
}  // namespace subscan::viewer
