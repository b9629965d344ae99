#include "render/PresentPass.h"

#include "shared/bindings.h"

namespace subscan {

PresentPass::PresentPass(const ShaderSources& sources, std::string colorInput,
                         std::string depthInput)
    : colorInput_(std::move(colorInput)),
      depthInput_(std::move(depthInput)),
      program_(Program::compute(
          sources, "render/Present.comp",
          depthInput_.empty() ? "#define HAS_DEPTH 0\n" : "#define HAS_DEPTH 1\n")) {}

std::vector<std::string_view> PresentPass::inputs() const {
    if (depthInput_.empty()) {
        return {colorInput_};
    }
    return {colorInput_, depthInput_};
}

void PresentPass::execute(FrameContext& frame) {
    Texture& image =
        frame.resources.ensureTexture("image", TextureFormat::RGBA8, frame.width(), frame.height());
    frame.resources.texture(colorInput_).bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    if (!depthInput_.empty()) {
        frame.resources.texture(depthInput_).bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    }
    image.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    program_.use();
    Program::dispatch2D(frame.width(), frame.height(), SUBSCAN_IMAGE_GROUP_SIZE,
                        SUBSCAN_IMAGE_GROUP_SIZE);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace subscan
