#include "render/NormalsPass.h"

#include "render/Pyramid.h"

namespace subscan {

NormalsPass::NormalsPass(const ShaderSources& sources)
    : stages_(sources, "render/Normals.comp", {"LEVEL", "BLEND"}) {}

std::vector<std::string_view> NormalsPass::inputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"pushValues", "pullWeights"};
    if (usesPointNormals(settings)) {
        names.push_back("normalPyramid");  // PullPushPass's
    }
    if (levelZero_ == LevelZero::PerPass) {
        names.push_back("surfaceDepth");
    }
    return names;
}

std::vector<std::string_view> NormalsPass::outputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names;
    if (!usesPointNormals(settings)) {
        names.push_back("normalPyramid");
    }
    if (levelZero_ == LevelZero::PerPass) {
        names.push_back("normals");
    }
    return names;
}

void NormalsPass::execute(FrameContext& frame) {
    FrameResources& resources = frame.resources;
    Buffer& normalPyramid =
        resources.ensureBuffer("normalPyramid", pyramidTexels(frame.pyramid) * 4 * sizeof(float));
    normalPyramid.bindStorage(SUBSCAN_SSBO_NORMALS);
    normalPyramid.bindTexels(SUBSCAN_TEXELS_NORMALS, TextureFormat::RGBA32F);
    resources.buffer("pushValues").bindTexels(SUBSCAN_TEXELS_PUSH_VALUES, TextureFormat::RGBA32F);
    // Which texels points cover (the tangents' and the blend's preference), and the local
    // spacing that scales the smoothing radius (PullPush.glsl's spacingRatioAt).
    resources.buffer("pullWeights").bindTexels(SUBSCAN_TEXELS_PULL_WEIGHTS, TextureFormat::RG32F);
    // From level 1: the blend never reads level 0 (its smoothing level is at least 1), and the
    // push leaves level 0 in the filled images only. The points' own normals are pushed by
    // PullPushPass instead.
    if (!usesPointNormals(frame.settings)) {
        for (unsigned level = 1; level < frame.pyramid.info.x; ++level) {
            stages_.runOverRegion(Level, frame.region(level), level);
        }
        glMemoryBarrier(kPyramidWritesBarrier);
    }
    if (levelZero_ == LevelZero::Fused) {
        return;
    }
    Texture& normals = frame.imageOverRegion("normals", TextureFormat::RGBA16F);
    resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    normals.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    stages_.runOverRegion(Blend, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
