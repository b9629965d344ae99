// Loading a streamed view's nodes (lod::loadStreamedScan) where one of them cannot be read: the
// rest load, and the points around the missing node take the spacing of the level they were
// actually loaded to.
#include "lod/NodeSelection.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"

namespace subscan::lod {
namespace {

constexpr double kRootSpacing = 0.5;

/// The cube [-1, 1]^3: a root holding a point in each octant, the 8 octants (level 1) a point
/// each, and below each octant the node of level 2 that holds the root's point there. The
/// octant at the lowest corner (node 1-0-0-0) cannot be read.
class OctantSource final : public NodeSource {
  public:
    OctantSource() {
        info_.name = "octants";
        info_.cube = OctreeCube{glm::dvec3(0.0), 1.0, kRootSpacing};
        info_.bounds.add(glm::dvec3(-1.0));
        info_.bounds.add(glm::dvec3(1.0));
        std::vector<StreamedNode> nodes{{laz::VoxelKey{0, 0, 0, 0}, 8}};
        for (int octant = 0; octant < 8; ++octant) {
            const int x = octant & 1, y = (octant >> 1) & 1, z = octant >> 2;
            nodes.push_back({laz::VoxelKey{1, x, y, z}, 1});
            nodes.push_back({laz::VoxelKey{2, 1 + x, 1 + y, 1 + z}, 1});
        }
        info_.points = 8 + 8 + 8;
        setNodes(std::move(nodes));
    }

    PointCloud load(std::size_t index) const override {
        const laz::VoxelKey key = nodes()[index].key;
        if (key.level == 1 && key.x == 0 && key.y == 0 && key.z == 0) {
            throw Error("node 1-0-0-0: the tile is truncated");
        }
        PointCloud cloud;
        const auto add = [&](const glm::dvec3& position) {
            cloud.positions.emplace_back(position);
            cloud.bounds.add(position);
        };
        if (key.level == 0) {
            for (int octant = 0; octant < 8; ++octant) {
                add(glm::dvec3(octant & 1 ? 0.25 : -0.25, (octant >> 1) & 1 ? 0.25 : -0.25,
                               octant >> 2 ? 0.25 : -0.25));
            }
        } else {
            // Within the node's cube, off the root's points.
            const double side = 2.0 / (1 << key.level);
            add(glm::dvec3(-1.0) + side * (glm::dvec3(key.x, key.y, key.z) + 0.3));
        }
        return cloud;
    }
};

TEST(NodeSelectionTest, ANodeThatCannotBeReadLeavesItsCubeAtItsParentsSpacing) {
    const OctantSource source;
    // The root and every octant, not the level below: the view cut the octree at level 1.
    std::vector<std::size_t> nodes{source.find({0, 0, 0, 0})};
    for (int octant = 0; octant < 8; ++octant) {
        nodes.push_back(source.find({1, octant & 1, (octant >> 1) & 1, octant >> 2}));
    }
    const LoadedScan scan = loadStreamedScan(source, nodes);
    ASSERT_EQ(scan.cloud.size(), 8u + 7u);  // the broken octant's one point is missing
    ASSERT_EQ(scan.levelSpacing.size(), scan.cloud.size());
    ASSERT_EQ(scan.warnings.size(), 1u);
    EXPECT_THAT(scan.warnings[0], ::testing::HasSubstr("1-0-0-0"));
    int checked = 0;
    for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
        const glm::dvec3 position = scan.cloud.fileCoordinates(i);
        const bool inBrokenOctant = glm::all(glm::lessThan(position, glm::dvec3(0.0)));
        const bool rootPoint = std::abs(std::abs(position.x) - 0.25) < 1e-6 &&
                               std::abs(std::abs(position.y) - 0.25) < 1e-6 &&
                               std::abs(std::abs(position.z) - 0.25) < 1e-6;
        if (inBrokenOctant) {
            // Only the root's point is there: loaded to level 0, where the view left out the
            // level below. Counted as loaded, the octant that failed gave it level 1's.
            EXPECT_TRUE(rootPoint);
            EXPECT_FLOAT_EQ(scan.levelSpacing[i], static_cast<float>(kRootSpacing)) << i;
            ++checked;
        } else if (glm::all(glm::greaterThan(position, glm::dvec3(0.0)))) {
            // The far corner's octant was read, and the view left out the level-2 node below
            // it: level 1's spacing. But the root's point there lies within the root's
            // spacing of the broken octant's cube (0.43 from it), a part of the view at the
            // root's level: it takes that, while the octant's own point (0.52 from it) does not.
            EXPECT_FLOAT_EQ(scan.levelSpacing[i],
                            static_cast<float>(rootPoint ? kRootSpacing : kRootSpacing / 2))
                << i;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 3);

    std::vector<std::string> warnings;
    std::vector<std::size_t> read;
    const PointCloud cloud = loadNodes(source, nodes, warnings, 1, {}, &read);
    EXPECT_EQ(cloud.size(), 15u);
    ASSERT_EQ(read.size(), 8u);
    EXPECT_EQ(read.front(), nodes.front());
    for (const std::size_t node : read) {
        EXPECT_NE(nodeName(source.nodes()[node].key), "node 1-0-0-0");
    }
}

/// One node of three points as a LAS tile gives them, on a grid of 0.01 with its 16-bit colour
/// cut to 8 bits, and with normals that are the zeros some exporters write (an index of such a
/// file keeps them).
class OneTileSource final : public NodeSource {
  public:
    OneTileSource() {
        info_.name = "zeros";
        info_.cube = OctreeCube{glm::dvec3(0.0), 1.0, kRootSpacing};
        info_.bounds.add(glm::dvec3(-1.0));
        info_.bounds.add(glm::dvec3(1.0));
        info_.points = 3;
        setNodes({{laz::VoxelKey{0, 0, 0, 0}, 3}});
    }

    PointCloud load(std::size_t) const override {
        PointCloud cloud;
        for (const glm::dvec3 position :
             {glm::dvec3(0.0), glm::dvec3(0.5, 0, 0), glm::dvec3(0, 0.5, 0)}) {
            cloud.positions.emplace_back(position);
            cloud.bounds.add(position);
            cloud.normals.emplace_back(0.0f);
            cloud.colors.emplace_back();
        }
        cloud.coordinateStep = 0.01;
        cloud.colorCutTo8Bits = true;
        return cloud;
    }
};

TEST(NodeSelectionTest, NodesWhoseNormalsAreAllZeroHaveNone) {
    // As a whole file's: the surface was shaded flat with them.
    const OneTileSource source;
    std::vector<std::string> warnings;
    const std::vector<std::size_t> nodes{0};
    const PointCloud cloud = loadNodes(source, nodes, warnings);
    EXPECT_EQ(cloud.size(), 3u);
    EXPECT_FALSE(cloud.hasNormals());
    EXPECT_THAT(warnings, ::testing::ElementsAre(::testing::HasSubstr("normals are all zero")));
}

TEST(NodeSelectionTest, NodesKeepTheirGridAndSayTheirColourWasCut) {
    // What convert's PLY and PCD output of an EPT dataset decide by: doubles where floats lose
    // the grid, and a warning for the 16 bits of colour they do not hold.
    const OneTileSource source;
    std::vector<std::string> warnings;
    const std::vector<std::size_t> nodes{0};
    const PointCloud cloud = loadNodes(source, nodes, warnings);
    EXPECT_EQ(cloud.coordinateStep, 0.01);
    EXPECT_TRUE(cloud.colorCutTo8Bits);
}

}  // namespace
}  // namespace subscan::lod
