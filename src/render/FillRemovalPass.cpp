#include "render/FillRemovalPass.h"

#include <limits>

namespace subscan {

FillRemovalPass::FillRemovalPass(const ShaderSources& sources)
    : stages_(sources, "render/FillRemoval.comp", {"ALL"}) {}

void FillRemovalPass::execute(FrameContext& frame) {
    FrameResources& resources = frame.resources;
    Texture& mask =
        resources.ensureTexture("mask", TextureFormat::R8, frame.width(), frame.height());
    Texture& surfaceDepth =
        resources.ensureTexture("surfaceDepth", TextureFormat::R32F, frame.width(), frame.height());
    resources.buffer("pullWeights").bindStorage(SUBSCAN_SSBO_PULL_WEIGHTS);
    resources.texture("filledDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    mask.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    surfaceDepth.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    if (frame.restricted()) {
        mask.clear();
        surfaceDepth.clear(glm::vec4(std::numeric_limits<float>::infinity()));
    }
    stages_.runOverRegion(0, frame.region(0));
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace subscan
