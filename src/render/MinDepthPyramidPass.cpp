#include "render/MinDepthPyramidPass.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "render/Pyramid.h"

namespace subscan {

namespace {

constexpr std::uint32_t kInfinityBits = 0x7F800000u;

/// How many pixels beyond its outermost points fill removal may keep a sparse surface, at
/// most (FillRemoval.glsl's sparseEnclosure): SUBSCAN_BEYOND_OUTERMOST_POINTS times 1 - 1/R of
/// the expected gap fillRadius h R, R a pixel's spacing ratio on screen, so fillRadius h (R - 1),
/// in pixels at the nearest point's depth `nearest`, and beside the lines' axis by the walk's
/// 1.5 texels (pointAcrossWithin: texels of at most sqrt 2 times a quarter of the reach or of
/// the gap, the gap along the lines being below half the gap). R is at most the cloud's
/// sparse ratio
/// (GpuPointCloud::sparseSpacingRatio: the sparsest 0.1 % of the points may still reach past
/// the region), its across-lines vector projected to first order grown by the view's widest
/// |xy| / depth; without local spacing (ratio 1) nothing reaches beyond the points. Plus a
/// pixel: the reach is measured from a level-1 texel's centre.
int beyondReachPixels(const FrameContext& frame, float nearest) {
    const float ratio = frame.cloud.sparseSpacingRatio();
    if (!frame.settings.surface.localSpacing || !frame.cloud.hasLocalSpacing() || ratio <= 1.0f ||
        !std::isfinite(nearest) || !(nearest > 0.0f)) {
        return 0;
    }
    const Camera& camera = frame.camera;
    const double focal = camera.focalLengthPixels();
    const double offAxis =
        camera.orthographic() ? 0.0 : 0.5 * std::hypot(camera.width, camera.height) / focal;
    const double perUnit = camera.orthographic() ? focal : focal / nearest;
    const double screenRatio = ratio * (1.0 + offAxis);
    const double gap = frame.settings.surface.fillRadius * frame.spacing * screenRatio * perUnit;
    const double reach = SUBSCAN_BEYOND_OUTERMOST_POINTS * gap * (1.0 - 1.0 / screenRatio);
    const double beside = 1.5 * std::sqrt(2.0) * 0.25 * std::max(reach, gap);
    return static_cast<int>(std::min(std::ceil(std::hypot(reach, beside) + 1.0), 1.0e6));
}

}  // namespace

MinDepthPyramidPass::MinDepthPyramidPass(const ShaderSources& sources)
    : stages_(sources, "render/MinDepthPyramid.comp", {"FIRST", "REDUCE", "BOUNDS"}),
      bounds_(sizeof(glm::ivec4), nullptr, "MinDepthPyramid.bounds") {}

void MinDepthPyramidPass::execute(FrameContext& frame) {
    Buffer& pyramid =
        frame.resources.ensureBuffer("pyramid", pyramidTexels(frame.pyramid) * sizeof(float));
    pyramid.bindStorage(SUBSCAN_SSBO_PYRAMID);
    pyramid.bindTexels(SUBSCAN_TEXELS_PYRAMID, TextureFormat::R32F);
    // Read only where the pyramid holds a depth, and written wherever it does: no clear.
    Buffer& centroids = frame.resources.ensureBuffer(
        "pointCentroids", pyramidTexels(frame.pyramid) * sizeof(std::uint32_t));
    centroids.bindStorage(SUBSCAN_SSBO_POINT_CENTROIDS);
    centroids.bindTexels(SUBSCAN_TEXELS_POINT_CENTROIDS, TextureFormat::R32UI);
    frame.resources.texture("depth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    if (frame.settings.surface.localSpacing) {
        frame.resources.texture("color").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
        Buffer& frontSpacing = frame.resources.ensureBuffer(
            "frontSpacing", pyramidTexels(frame.pyramid) * sizeof(float));
        frontSpacing.bindStorage(SUBSCAN_SSBO_FRONT_SPACING);
        frontSpacing.bindTexels(SUBSCAN_TEXELS_FRONT_SPACING, TextureFormat::R32F);
    }
    // Levels 0 and 1 are copied only where the cloud's bounding box projects: elsewhere the
    // depth is +inf, as the fill leaves it.
    frame.fill(pyramid, kInfinityBits);
    // One invocation per level-1 texel (also for a one-pixel image, which has no level 1).
    const TexelRegion pixels = frame.cloudRegion();
    const glm::ivec2 first = pixels.origin / 2;
    const glm::ivec2 end = (pixels.origin + pixels.size + 1) / 2;
    stages_.runOverRegion(First, {first, end - first}, 1);
    for (unsigned level = 2; level < frame.pyramid.info.x; ++level) {
        glMemoryBarrier(kPyramidWritesBarrier);
        const auto& size = frame.pyramid.levels[level];
        stages_.runOverImage(Reduce, static_cast<int>(size.y), static_cast<int>(size.z), level);
    }
    glMemoryBarrier(kPyramidWritesBarrier);
    frame.pointBounds.reset();
    if (surfaceBoundsAllowed(frame.settings)) {
        frame.pointBounds = measureBounds(frame);
    }
}

glm::ivec4 MinDepthPyramidPass::measureBounds(const FrameContext& frame) {
    // Level 4 texels are 16 pixels wide: few atomics, and bounds at most 15 pixels too wide.
    const unsigned level = std::min(4u, frame.pyramid.info.x - 1);
    const glm::ivec4 empty(std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), -1,
                           -1);
    bounds_.upload(0, sizeof(empty), &empty);
    bounds_.bindStorage(SUBSCAN_SSBO_POINT_BOUNDS);
    const auto& size = frame.pyramid.levels[level];
    stages_.runOverImage(Bounds, static_cast<int>(size.y), static_cast<int>(size.z), level);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    // Reading back waits for the frame so far: free on llvmpipe, which finishes every pass
    // anyway; on a GPU an indirect dispatch would avoid the stall.
    glm::ivec4 texels;
    bounds_.download(0, sizeof(texels), &texels);
    if (texels.z < 0) {
        return glm::ivec4(0);
    }
    // The top level holds the nearest depth of all.
    float nearest = 0.0f;
    frame.resources.buffer("pyramid").download((pyramidTexels(frame.pyramid) - 1) * sizeof(float),
                                               sizeof(float), &nearest);
    const int reach = beyondReachPixels(frame, nearest);
    const int scale = 1 << level;
    return {std::max(texels.x * scale - reach, 0), std::max(texels.y * scale - reach, 0),
            static_cast<int>(
                std::min<std::int64_t>(std::int64_t{texels.z + 1} * scale + reach, frame.width())),
            static_cast<int>(std::min<std::int64_t>(std::int64_t{texels.w + 1} * scale + reach,
                                                    frame.height()))};
}

}  // namespace subscan
