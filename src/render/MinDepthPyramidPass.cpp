#include "render/MinDepthPyramidPass.h"

#include <algorithm>
#include <cstdint>
#include <limits>

#include "render/Pyramid.h"

namespace subscan {

namespace {

constexpr std::uint32_t kInfinityBits = 0x7F800000u;

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
    const int scale = 1 << level;
    return {texels.x * scale, texels.y * scale, std::min((texels.z + 1) * scale, frame.width()),
            std::min((texels.w + 1) * scale, frame.height())};
}

}  // namespace subscan
