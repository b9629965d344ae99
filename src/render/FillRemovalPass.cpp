#include "render/FillRemovalPass.h"

#include <cstdint>
#include <limits>

#include "render/Pyramid.h"

namespace subscan {

FillRemovalPass::FillRemovalPass(const ShaderSources& sources)
    : stages_(sources, "render/FillRemoval.comp", {"REACH", "MASK", "SURFACE_DEPTH"}) {}

std::vector<std::string_view> FillRemovalPass::inputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"pullWeights", "pushValues", "pyramid", "pointCentroids"};
    if (settings.surface.localSpacing) {
        names.push_back("pullAxes");
    }
    if (levelZero_ == LevelZero::Fused) {
        if (!followsNormalsToOutline(settings)) {
            return names;
        }
        names.push_back("pullValues");
    } else {
        names.push_back("filledDepth");
    }
    if (placesOutlineBySubpixels(settings)) {
        names.push_back("occupancy");
    }
    return names;
}

std::vector<std::string_view> FillRemovalPass::outputs(const RenderSettings& settings) const {
    if (levelZero_ == LevelZero::PerPass) {
        return {"fillReach", "fillSparse", "mask", "surfaceDepth"};
    }
    if (followsNormalsToOutline(settings)) {
        return {"fillReach", "fillSparse", "mask", "surfaceDepth"};
    }
    return {"fillReach", "fillSparse"};
}

void FillRemovalPass::execute(FrameContext& frame) {
    FrameResources& resources = frame.resources;
    resources.buffer("pullWeights").bindTexels(SUBSCAN_TEXELS_PULL_WEIGHTS, TextureFormat::RG32F);
    resources.buffer("pushValues").bindTexels(SUBSCAN_TEXELS_PUSH_VALUES, TextureFormat::RGBA32F);
    resources.buffer("pyramid").bindTexels(SUBSCAN_TEXELS_PYRAMID, TextureFormat::R32F);
    if (frame.settings.surface.localSpacing) {
        resources.buffer("pullAxes").bindTexels(SUBSCAN_TEXELS_PULL_AXES, TextureFormat::RGBA32F);
    }
    resources.buffer("pointCentroids")
        .bindTexels(SUBSCAN_TEXELS_POINT_CENTROIDS, TextureFormat::R32UI);
    Buffer& fillReach =
        resources.ensureBuffer("fillReach", pyramidTexels(frame.pyramid) * sizeof(std::uint32_t));
    fillReach.bindStorage(SUBSCAN_SSBO_FILL_REACH);
    fillReach.bindTexels(SUBSCAN_TEXELS_FILL_REACH, TextureFormat::R32UI);
    // One word per level-1 texel (at least one: a one-pixel image has no level 1).
    const std::size_t levelOneTexels =
        frame.pyramid.info.x > 1
            ? std::size_t{frame.pyramid.levels[1].y} * std::size_t{frame.pyramid.levels[1].z}
            : 1;
    Buffer& fillSparse =
        resources.ensureBuffer("fillSparse", levelOneTexels * sizeof(std::uint32_t));
    fillSparse.bindStorage(SUBSCAN_SSBO_FILL_SPARSE);
    fillSparse.bindTexels(SUBSCAN_TEXELS_FILL_SPARSE, TextureFormat::R32UI);
    // Coarsest first: every level reads its parent's answer. Level 0 is part of the mask stage.
    for (unsigned level = frame.pyramid.info.x; level-- > 1;) {
        stages_.runOverRegion(Reach, frame.region(level), level);
        glMemoryBarrier(kPyramidWritesBarrier);
    }
    const bool fused = levelZero_ == LevelZero::Fused;
    if (fused && !followsNormalsToOutline(frame.settings)) {
        return;
    }
    Texture& surfaceDepth = frame.imageOverRegion(
        "surfaceDepth", TextureFormat::R32F, glm::vec4(std::numeric_limits<float>::infinity()));
    if (placesOutlineBySubpixels(frame.settings)) {
        resources.buffer("occupancy").bindStorage(SUBSCAN_SSBO_OCCUPANCY);
    }
    surfaceDepth.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    frame.imageOverRegion("mask", TextureFormat::R8).bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    if (fused) {
        // Level 0 of the push, as FinishSurface computes it.
        resources.buffer("pullValues")
            .bindTexels(SUBSCAN_TEXELS_PULL_VALUES, TextureFormat::RGBA32F);
    } else {
        resources.texture("filledDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    }
    stages_.runOverRegion(fused ? SurfaceDepth : Mask, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
