#include "render/PresentPass.h"

#include "shared/bindings.h"

namespace subscan {

PresentPass::PresentPass(const ShaderSources& sources)
    : program_(Program::compute(sources, "render/Present.comp")) {}

void PresentPass::execute(FrameContext& frame) {
    const int width = frame.camera.width;
    const int height = frame.camera.height;
    Texture& image = frame.resources.ensureTexture("image", TextureFormat::RGBA8, width, height);
    frame.resources.texture("color").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    frame.resources.texture("depth").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    image.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    program_.use();
    Program::dispatch2D(width, height, SUBSCAN_IMAGE_GROUP_SIZE, SUBSCAN_IMAGE_GROUP_SIZE);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace subscan
