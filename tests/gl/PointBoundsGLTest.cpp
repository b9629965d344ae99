// The passes after rasterization skip the screen outside the points' bounds
// (SurfaceSettings::restrictToPoints). The bounds must hold every point, and a restricted frame
// must equal the whole-frame computation bit for bit in every image that leaves the pipeline,
// even when the images still hold an earlier frame.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/FillRemovalPass.h"
#include "render/HiddenPointRemovalPass.h"
#include "render/MinDepthPyramidPass.h"
#include "render/NormalsPass.h"
#include "render/PresentPass.h"
#include "render/PullPushPass.h"
#include "render/ShadePass.h"
#include "render/SubsurfaceScatteringPass.h"
#include "support/PassHarness.h"

namespace subscan {
namespace {

using test::PassHarness;

constexpr int kWidth = 160;
constexpr int kHeight = 96;
constexpr float kInf = std::numeric_limits<float>::infinity();
// h: the patch's points are about this far apart at depth 5 (a pixel is 0.05 there).
constexpr double kSpacing = 0.05;

struct Patch {
    int x0, y0, x1, y1;  // pixels [x0, x1) x [y0, y1) may hold points
};

/// A dome of points with 40 % gaps inside `patch` (or the whole frame), random colours.
void uploadPoints(PassHarness& harness, const Patch& patch, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> depth(kWidth * kHeight, kInf);
    std::vector<float> color(kWidth * kHeight * 4, 1.0f);
    for (int y = patch.y0; y < patch.y1; ++y) {
        for (int x = patch.x0; x < patch.x1; ++x) {
            if (unit(random) < 0.4f) {
                continue;
            }
            const float u = (x - patch.x0) / float(patch.x1 - patch.x0) - 0.5f;
            const float v = (y - patch.y0) / float(patch.y1 - patch.y0) - 0.5f;
            const int i = y * kWidth + x;
            depth[i] = 5.0f + 2.0f * (u * u + v * v);
            for (int c = 0; c < 3; ++c) {
                color[4 * i + c] = unit(random);
            }
        }
    }
    FrameResources& resources = harness.resources();
    resources.ensureTexture("depth", TextureFormat::R32F, kWidth, kHeight).uploadFloats(depth);
    resources.ensureTexture("color", TextureFormat::RGBA16F, kWidth, kHeight).uploadFloats(color);
}

RenderSettings boundsSettings(bool restrict) {
    RenderSettings settings;
    settings.surface.restrictToPoints = restrict;
    // Kernels of about 10 pixels, so scattering taps reach well past the points' bounds.
    settings.scattering.scale = 300.0f;
    return settings;
}

/// The whole surface pipeline on one frame; returns the frame's bounds.
std::optional<glm::ivec4> runFrame(PassHarness& harness) {
    const ShaderSources& sources = harness.sources();
    FrameContext frame = harness.context();
    MinDepthPyramidPass(sources).execute(frame);
    HiddenPointRemovalPass(sources).execute(frame);
    PullPushPass(sources).execute(frame);
    FillRemovalPass(sources).execute(frame);
    NormalsPass(sources).execute(frame);
    ShadePass(sources, ShadeOutputs::Split).execute(frame);
    SubsurfaceScatteringPass(sources).execute(frame);
    PresentPass(sources, "scatteredRadiance", PresentBackground::WhereNoDepth, "surfaceDepth")
        .execute(frame);
    return frame.pointBounds;
}

const Patch kPatch{52, 31, 99, 70};

TEST(PointBoundsGLTest, BoundsHoldEveryPointAndLittleElse) {
    PassHarness harness(kWidth, kHeight, boundsSettings(true), kSpacing);
    uploadPoints(harness, kPatch, 1);
    const std::optional<glm::ivec4> bounds = runFrame(harness);
    ASSERT_TRUE(bounds.has_value());
    const std::vector<float> depth = harness.resources().texture("depth").readFloats();
    glm::ivec4 tight(kWidth, kHeight, 0, 0);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            if (!std::isinf(depth[y * kWidth + x])) {
                tight = {std::min(tight.x, x), std::min(tight.y, y), std::max(tight.z, x + 1),
                         std::max(tight.w, y + 1)};
            }
        }
    }
    // Measured on 16-pixel texels: at most 15 pixels too wide on each side, never too narrow.
    EXPECT_LE(bounds->x, tight.x);
    EXPECT_LE(bounds->y, tight.y);
    EXPECT_GE(bounds->z, tight.z);
    EXPECT_GE(bounds->w, tight.w);
    EXPECT_GT(bounds->x, tight.x - 16);
    EXPECT_GT(bounds->y, tight.y - 16);
    EXPECT_LT(bounds->z, tight.z + 16);
    EXPECT_LT(bounds->w, tight.w + 16);
}

TEST(PointBoundsGLTest, NoBoundsWhereTheFillCouldLeaveThemOrAStageIsShown) {
    RenderSettings fewDirections = boundsSettings(true);
    fewDirections.surface.fillDirections = 5;
    RenderSettings stage = boundsSettings(true);
    stage.raster.stage = Stage::Push;
    for (const RenderSettings& settings : {boundsSettings(false), fewDirections, stage}) {
        PassHarness harness(kWidth, kHeight, settings, kSpacing);
        uploadPoints(harness, kPatch, 1);
        FrameContext frame = harness.context();
        MinDepthPyramidPass(harness.sources()).execute(frame);
        EXPECT_FALSE(frame.pointBounds.has_value());
        EXPECT_EQ(frame.region(0).size, glm::ivec2(kWidth, kHeight));
    }
}

TEST(PointBoundsGLTest, AnEmptyFrameHasAnEmptyRegion) {
    PassHarness harness(kWidth, kHeight, boundsSettings(true), kSpacing);
    uploadPoints(harness, {0, 0, 0, 0}, 1);
    FrameContext frame = harness.context();
    MinDepthPyramidPass(harness.sources()).execute(frame);
    ASSERT_TRUE(frame.pointBounds.has_value());
    EXPECT_EQ(frame.region(0).size, glm::ivec2(0));
}

TEST(PointBoundsGLTest, AnImageReadOneTexelOffTheRegionIsClearedOnlyThere) {
    // Points within [40, 100) x [30, 60): the region adds its margin. An image read one texel
    // off the region has exactly that ring cleared, corners included; what lies further out
    // keeps what it held (never read), and so does the region (the pass writes it).
    PassHarness harness(kWidth, kHeight, boundsSettings(true), kSpacing);
    FrameContext frame = harness.context();
    frame.pointBounds = glm::ivec4(40, 30, 100, 60);
    const TexelRegion region = frame.region(0);
    ASSERT_GT(region.origin.x, 1);
    ASSERT_LT(region.origin.x + region.size.x, kWidth - 1);
    harness.resources()
        .ensureTexture("ringed", TextureFormat::R32F, kWidth, kHeight)
        .clear(glm::vec4(7.0f));
    const std::vector<float> values =
        frame.imageOverRegion("ringed", TextureFormat::R32F, 1, glm::vec4(-1.0f)).readFloats();
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const glm::ivec2 inside = glm::ivec2(x, y) - region.origin;
            const glm::ivec2 beyond = inside - region.size + 1;
            // Texels from the region's nearest texel, along the farther axis.
            const int distance = std::max({-inside.x, -inside.y, beyond.x, beyond.y, 0});
            EXPECT_EQ(values[y * kWidth + x], distance == 1 ? -1.0f : 7.0f)
                << "at " << x << "," << y;
        }
    }
}

TEST(PointBoundsGLTest, RestrictedFrameEqualsTheWholeFrame) {
    PassHarness whole(kWidth, kHeight, boundsSettings(false), kSpacing);
    uploadPoints(whole, kPatch, 2);
    ASSERT_FALSE(runFrame(whole).has_value());

    PassHarness restricted(kWidth, kHeight, boundsSettings(true), kSpacing);
    // An earlier frame with points everywhere leaves every image full of other values.
    uploadPoints(restricted, {0, 0, kWidth, kHeight}, 3);
    runFrame(restricted);
    uploadPoints(restricted, kPatch, 2);
    const std::optional<glm::ivec4> bounds = runFrame(restricted);
    ASSERT_TRUE(bounds.has_value());
    // The test means something only if most of the frame was skipped.
    ASSERT_LT((bounds->z - bounds->x) * (bounds->w - bounds->y), kWidth * kHeight / 2);

    std::size_t surfacePixels = 0;
    for (const char* name : {"surfaceDepth", "mask", "normals", "radiance", "scatteredRadiance"}) {
        const std::vector<float> expected = whole.resources().texture(name).readFloats();
        const std::vector<float> actual = restricted.resources().texture(name).readFloats();
        ASSERT_EQ(actual.size(), expected.size()) << name;
        std::size_t differences = 0;
        for (std::size_t i = 0; i < expected.size(); ++i) {
            // Bit for bit: the same formulas on the same inputs in the same order.
            differences += actual[i] == expected[i] ? 0 : 1;
        }
        EXPECT_EQ(differences, 0u) << name;
        if (std::string(name) == "surfaceDepth") {
            for (float depth : expected) {
                surfacePixels += std::isinf(depth) ? 0 : 1;
            }
        }
    }
    // The final picture too, background included.
    EXPECT_EQ(restricted.resources().texture("image").readRgba8(),
              whole.resources().texture("image").readRgba8());
    // The patch's gaps are filled: more surface than points.
    EXPECT_GT(surfacePixels, 0.7 * (kPatch.x1 - kPatch.x0) * (kPatch.y1 - kPatch.y0));
}

}  // namespace
}  // namespace subscan
