#include "render/FinishSurfacePass.h"

#include <limits>

#include "core/Error.h"
#include "render/PresentPass.h"
#include "render/ShadePass.h"

namespace subscan {

FinishSurfacePass::FinishSurfacePass(const ShaderSources& sources, Output output)
    : sources_(sources), output_(output) {}

const ComputeStages& FinishSurfacePass::stagesFor(bool directionalLights) {
    std::optional<ComputeStages>& stages = directionalLights ? withLights_ : headLightOnly_;
    if (!stages) {
        const std::string lights = directionalLights ? "LIGHTS" : "HEAD_LIGHT";
        stages.emplace(
            sources_, "render/FinishSurface.comp",
            std::vector<std::string>{output_ == Output::Picture ? lights : lights + "_RADIANCE"});
    }
    return *stages;
}

void FinishSurfacePass::execute(FrameContext& frame) {
    if (!canFinish(frame.divisor, frame.pyramid)) {
        throw Error("FinishSurface needs a full-resolution frame of more than one pixel");
    }
    FrameResources& resources = frame.resources;
    resources.buffer("pullValues").bindTexels(SUBSCAN_TEXELS_PULL_VALUES, TextureFormat::RGBA32F);
    resources.buffer("pullWeights").bindTexels(SUBSCAN_TEXELS_PULL_WEIGHTS, TextureFormat::R32F);
    resources.buffer("pushValues").bindTexels(SUBSCAN_TEXELS_PUSH_VALUES, TextureFormat::RGBA32F);
    resources.buffer("fillReach").bindTexels(SUBSCAN_TEXELS_FILL_REACH, TextureFormat::R32UI);
    resources.buffer("normalPyramid").bindTexels(SUBSCAN_TEXELS_NORMALS, TextureFormat::RGBA32F);
    const gpu::ShadeParams shade = ShadePass::parameters(frame);
    params_.set(shade);
    params_.bind(SUBSCAN_UBO_PASS);
    const bool picture = output_ == Output::Picture;
    Texture& color = picture ? resources.ensureTexture("image", TextureFormat::RGBA8, frame.width(),
                                                       frame.height())
                             : resources.ensureTexture("radiance", TextureFormat::RGBA16F,
                                                       frame.width(), frame.height());
    Texture& surfaceDepth =
        resources.ensureTexture("surfaceDepth", TextureFormat::R32F, frame.width(), frame.height());
    color.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    surfaceDepth.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    if (frame.restricted()) {
        // Radiance off the surface is never read: surfaceDepth marks it.
        if (picture) {
            PresentPass::clearToBackground(color, frame.settings.raster);
        }
        surfaceDepth.clear(glm::vec4(std::numeric_limits<float>::infinity()));
    }
    stagesFor(shade.lightCount.x > 0).runOverRegion(0, frame.region(0));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace subscan
