#include "render/PullPushPass.h"

#include "render/Pyramid.h"

namespace subscan {

PullPushPass::PullPushPass(const ShaderSources& sources)
    : stages_(sources, "render/PullPush.comp", {"PULL_INIT", "PULL", "PUSH_TOP", "PUSH"}) {}

std::vector<std::string_view> PullPushPass::inputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"depth", "color", "visibility"};
    if (usesPointNormals(settings)) {
        names.push_back("pointNormals");
    }
    if (settings.surface.localSpacing) {
        names.push_back("acrossLines");
    }
    return names;
}

std::vector<std::string_view> PullPushPass::outputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"pullValues", "pullWeights", "pushValues"};
    if (settings.surface.localSpacing) {
        names.push_back("pullAxes");
    }
    if (levelZero_ == LevelZero::PerPass) {
        names.insert(names.end(), {"filledDepth", "filledColor"});
    }
    if (usesPointNormals(settings)) {
        names.push_back("normalPyramid");
    }
    return names;
}

void PullPushPass::execute(FrameContext& frame) {
    const std::size_t texels = pyramidTexels(frame.pyramid);
    FrameResources& resources = frame.resources;
    Buffer& pullValues = resources.ensureBuffer("pullValues", texels * 4 * sizeof(float));
    pullValues.bindStorage(SUBSCAN_SSBO_PULL_VALUES);
    pullValues.bindTexels(SUBSCAN_TEXELS_PULL_VALUES, TextureFormat::RGBA32F);
    Buffer& pullWeights = resources.ensureBuffer("pullWeights", texels * 2 * sizeof(float));
    pullWeights.bindStorage(SUBSCAN_SSBO_PULL_WEIGHTS);
    pullWeights.bindTexels(SUBSCAN_TEXELS_PULL_WEIGHTS, TextureFormat::RG32F);
    if (frame.restricted()) {
        // Pull and fill removal read weights around their region: there they must be zero.
        frame.fill(pullWeights, 0);
    }
    Buffer& pushValues = resources.ensureBuffer("pushValues", texels * 4 * sizeof(float));
    pushValues.bindStorage(SUBSCAN_SSBO_PUSH_VALUES);
    pushValues.bindTexels(SUBSCAN_TEXELS_PUSH_VALUES, TextureFormat::RGBA32F);
    resources.texture("depth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    resources.texture("color").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    resources.texture("visibility").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    if (frame.settings.surface.localSpacing) {
        resources.buffer("acrossLines").bindStorage(SUBSCAN_SSBO_ACROSS_LINES);
        Buffer& pullAxes = resources.ensureBuffer("pullAxes", texels * 4 * sizeof(float));
        pullAxes.bindStorage(SUBSCAN_SSBO_PULL_AXES);
        pullAxes.bindTexels(SUBSCAN_TEXELS_PULL_AXES, TextureFormat::RGBA32F);
    }
    if (usesPointNormals(frame.settings)) {
        // The points' normals are pulled and pushed beside the values (PullPush.comp).
        Buffer& normalPyramid = resources.ensureBuffer("normalPyramid", texels * 4 * sizeof(float));
        normalPyramid.bindStorage(SUBSCAN_SSBO_NORMALS);
        normalPyramid.bindTexels(SUBSCAN_TEXELS_NORMALS, TextureFormat::RGBA32F);
        resources.texture("pointNormals").bindImage(SUBSCAN_IMAGE_IN3, GL_READ_ONLY);
    }
    const bool perPass = levelZero_ == LevelZero::PerPass;
    if (perPass) {
        resources.ensureTexture("filledDepth", TextureFormat::R32F, frame.width(), frame.height())
            .bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
        resources
            .ensureTexture("filledColor", TextureFormat::RGBA16F, frame.width(), frame.height())
            .bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    }

    const unsigned levels = frame.pyramid.info.x;
    auto run = [&](Stage stage, unsigned level) {
        stages_.runOverRegion(stage, frame.region(level), level);
        glMemoryBarrier(kPyramidWritesBarrier);
    };
    run(PullInit, 0);
    for (unsigned level = 1; level < levels; ++level) {
        run(Pull, level);
    }
    run(PushTop, levels - 1);
    const unsigned lastLevel = perPass ? 0 : 1;
    for (unsigned level = levels - 1; level-- > lastLevel;) {
        run(Push, level);
    }
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
