// GpuPointCloudUpload: a cloud copied to the GPU a bounded number of bytes at a time holds, byte
// for byte, what one upload holds, and each step copies no more than it was given.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "render/GpuPointCloud.h"
#include "support/GlTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

constexpr std::size_t kPoints = 1000;
constexpr std::size_t kChunkPoints = 97;  // 11 chunks, the last one short

/// Points with intensities but no colours (their colours are made by the upload, not borrowed),
/// a local spacing and normals.
struct Scene {
    PointCloud cloud;
    PackedPointAttributes packed;
};

Scene makeScene() {
    Scene scene;
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<glm::vec4> spacing;
    std::vector<glm::vec3> normals;
    for (std::size_t i = 0; i < kPoints; ++i) {
        const glm::vec3 position(unit(random), unit(random), unit(random));
        scene.cloud.positions.push_back(position);
        scene.cloud.bounds.add(glm::dvec3(position));
        scene.cloud.intensities.push_back(100.0f + static_cast<float>(i % 50));
        spacing.emplace_back(unit(random), unit(random), 0.0f, 1.0f + unit(random) * 0.5f);
        normals.push_back(glm::normalize(position + glm::vec3(0.0f, 0.0f, 2.0f)));
    }
    scene.packed = packPointAttributes(spacing, normals);
    return scene;
}

/// Every chunk's buffers read back, one after the other.
struct Contents {
    std::vector<float> positions;
    std::vector<std::uint32_t> colors;
    std::vector<std::uint16_t> localSpacing;
    std::vector<std::uint32_t> normals;
    bool operator==(const Contents&) const = default;
};

Contents contentsOf(const GpuPointCloud& cloud) {
    Contents contents;
    const auto append = [](auto& all, const auto& part) {
        all.insert(all.end(), part.begin(), part.end());
    };
    for (const GpuPointCloud::Chunk& chunk : cloud.chunks()) {
        append(contents.positions, chunk.positions.read<float>());
        append(contents.colors, chunk.colors.read<std::uint32_t>());
        append(contents.localSpacing, chunk.localSpacing.read<std::uint16_t>());
        append(contents.normals, chunk.normals.read<std::uint32_t>());
    }
    return contents;
}

TEST(GpuPointCloudGLTest, AnUploadInStepsHoldsWhatOneUploadHolds) {
    const GlContext& context = test::glTestContext();
    const Scene scene = makeScene();
    GpuPointCloud whole(scene.cloud, context.capabilities(), kChunkPoints);
    whole.setLocalSpacing(scene.packed.localSpacing);
    whole.setNormals(scene.packed.normals);

    GpuPointCloudUpload started(scene.cloud, scene.packed, context.capabilities(), kChunkPoints);
    // Positions (12 bytes a point), colours (4), local spacing (8) and normals (4): copied, not
    // borrowed (PointMemory::Copy).
    const std::size_t total = kPoints * (12 + 4 + 8 + 4);
    EXPECT_EQ(started.bytesLeft(), total);
    // A step that does not divide a buffer's size: slices cross the buffers' ends. Halfway the
    // upload moves, as the viewer moves it into its pending nodes: what it copies from (its
    // own colours and attributes) must move with it.
    constexpr std::size_t kStep = 1000;
    std::optional<GpuPointCloudUpload> moved;
    GpuPointCloudUpload* upload = &started;
    std::size_t steps = 0;
    for (bool done = false; !done; ++steps) {
        if (steps == total / kStep / 2) {
            moved.emplace(std::move(started));
            upload = &*moved;
        }
        const std::size_t before = upload->bytesLeft();
        done = upload->advance(kStep);
        EXPECT_EQ(before - upload->bytesLeft(), std::min(kStep, before));
    }
    ASSERT_TRUE(moved.has_value());
    EXPECT_EQ(steps, (total + kStep - 1) / kStep);
    EXPECT_TRUE(moved->finished());
    const GpuPointCloud stepped = std::move(*moved).take();

    EXPECT_EQ(stepped.size(), kPoints);
    EXPECT_EQ(stepped.chunks().size(), (kPoints + kChunkPoints - 1) / kChunkPoints);
    EXPECT_TRUE(stepped.hasLocalSpacing());
    EXPECT_TRUE(stepped.hasNormals());
    EXPECT_EQ(stepped.sparseSpacingRatio(), whole.sparseSpacingRatio());
    const Contents contents = contentsOf(stepped);
    EXPECT_TRUE(contents == contentsOf(whole));
    // Against the sources themselves, so that both uploads being wrong alike fails too.
    const auto* positions = reinterpret_cast<const float*>(scene.cloud.positions.data());
    EXPECT_TRUE(std::equal(contents.positions.begin(), contents.positions.end(), positions));
    EXPECT_EQ(contents.colors, displayColors(scene.cloud));
    EXPECT_EQ(contents.normals, scene.packed.normals);
    const auto* halves =
        reinterpret_cast<const std::uint16_t*>(scene.packed.localSpacing.halves.data());
    EXPECT_TRUE(std::equal(contents.localSpacing.begin(), contents.localSpacing.end(), halves));
}

TEST(GpuPointCloudGLTest, BorrowedPointsAreNotCopiedAndTakingCopiesWhatIsLeft) {
    const GlContext& context = test::glTestContext();
    Scene scene = makeScene();
    scene.cloud.colors.assign(kPoints, Rgba8{10, 20, 30, 255});
    GpuPointCloudUpload upload(scene.cloud, scene.packed, context.capabilities(), kChunkPoints,
                               PointMemory::Borrow);
    // Where the driver reads client memory (llvmpipe does) the positions and the scan's own
    // colours are read in place: only the local spacing and the normals are left to copy.
    const std::size_t copied = kPoints * (8 + 4);
    const std::size_t borrowable = kPoints * (12 + 4);
    const std::size_t left = upload.bytesLeft();
    EXPECT_TRUE(left == copied || left == copied + borrowable) << left;
    upload.advance(5);
    const GpuPointCloud cloud = std::move(upload).take();
    EXPECT_EQ(cloud.borrowsPositions(), left == copied);
    const Contents contents = contentsOf(cloud);
    EXPECT_EQ(contents.normals, scene.packed.normals);
    EXPECT_EQ(contents.colors, displayColors(scene.cloud));
}

TEST(GpuPointCloudGLTest, AttributesOfAnotherCountAreRefused) {
    const GlContext& context = test::glTestContext();
    Scene scene = makeScene();
    scene.packed.normals.pop_back();
    EXPECT_THAT(test::errorMessage([&] {
                    GpuPointCloudUpload(scene.cloud, scene.packed, context.capabilities());
                }),
                ::testing::HasSubstr("999 normals given to a cloud of 1000 points"));
    scene = makeScene();
    scene.packed.localSpacing.halves.resize(5);
    EXPECT_THAT(test::errorMessage([&] {
                    GpuPointCloudUpload(scene.cloud, scene.packed, context.capabilities());
                }),
                ::testing::HasSubstr("local spacing for 5 points given to a cloud of 1000"));
}

}  // namespace
}  // namespace subscan
