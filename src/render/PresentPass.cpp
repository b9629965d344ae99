#include "render/PresentPass.h"

#include "core/Srgb.h"
#include "shared/bindings.h"

namespace subscan {

PresentPass::PresentPass(const ShaderSources& sources, std::string colorInput,
                         std::string depthInput)
    : colorInput_(std::move(colorInput)),
      depthInput_(std::move(depthInput)),
      stages_(sources, "render/Present.comp", {depthInput_.empty() ? "COLOR" : "DEPTH"}) {}

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
    if (depthInput_.empty() || !frame.restricted()) {
        stages_.runOverImage(0, frame.width(), frame.height());
    } else {
        // The background exactly as the shader encodes it: linear (the frame uniform) to sRGB.
        const glm::vec3& background = frame.settings.raster.backgroundSrgb;
        image.clear(glm::vec4(linearToSrgb(srgbToLinear(background.r)),
                              linearToSrgb(srgbToLinear(background.g)),
                              linearToSrgb(srgbToLinear(background.b)), 1.0f));
        stages_.runOverRegion(0, frame.region(0));
    }
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
}

}  // namespace subscan
