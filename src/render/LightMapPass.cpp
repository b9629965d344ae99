#include "render/LightMapPass.h"

namespace subscan {

LightMapPass::LightMapPass(const ShaderSources& sources)
    : stages_(sources, "render/LightMap.comp", {"PACK"}) {}

void LightMapPass::execute(FrameContext& frame) {
    Texture& lightMap = frame.resources.ensureTexture("lightMap", TextureFormat::RGBA32F,
                                                      frame.width(), frame.height());
    frame.resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    frame.resources.texture("normals").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    lightMap.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    // Every texel: the map is read anywhere a shaded point projects, and the surface depth is
    // +inf outside the points' region.
    stages_.runOverImage(0, frame.width(), frame.height());
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
