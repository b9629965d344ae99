#include "render/PresentPass.h"

#include "core/Srgb.h"
#include "shared/bindings.h"

namespace subscan {

namespace {

/// The output pixels whose bilinear taps reach the pipeline's region: the rest read only
/// texels outside it, which hold no surface and so show the background.
TexelRegion outputRegion(const FrameContext& frame) {
    const TexelRegion region = frame.region(0);
    if (frame.divisor == 1 || region.size.x <= 0 || region.size.y <= 0) {
        return region;
    }
    const int d = frame.divisor;
    // Output pixel p reads texels floor(q) and floor(q) + 1 of the reduced position q;
    // reducedPosition() inverted, with a pixel to spare for the rounding.
    const glm::dvec2 outputCentre = 0.5 * glm::dvec2(frame.outputSize());
    const glm::dvec2 pipelineCentre(0.5 * frame.width(), 0.5 * frame.height());
    auto toOutput = [&](glm::dvec2 texel) {
        return (texel - pipelineCentre) * double(d) + outputCentre;
    };
    const glm::ivec2 first = glm::max(
        glm::ivec2(glm::floor(toOutput(glm::dvec2(region.origin) - 0.5))) - 1, glm::ivec2(0));
    const glm::ivec2 last =
        glm::min(glm::ivec2(glm::ceil(toOutput(glm::dvec2(region.origin + region.size) + 0.5))) + 1,
                 frame.outputSize() - 1);
    return {first, glm::max(last - first + 1, glm::ivec2(0))};
}

}  // namespace

void PresentPass::clearToBackground(const FrameContext& frame, Texture& image) {
    // Linear (the frame uniform) to sRGB, as the shader does.
    const glm::vec3& background = frame.settings.raster.backgroundSrgb;
    frame.clear(image, glm::vec4(linearToSrgb(srgbToLinear(background.r)),
                                 linearToSrgb(srgbToLinear(background.g)),
                                 linearToSrgb(srgbToLinear(background.b)), 1.0f));
}

namespace {

const char* variantFor(PresentBackground background) {
    switch (background) {
        case PresentBackground::InColor:
            return "COLOR";
        case PresentBackground::WhereNoDepth:
            return "DEPTH";
        case PresentBackground::ByCoverage:
            return "COVERAGE";
    }
    return "COLOR";
}

}  // namespace

PresentPass::PresentPass(const ShaderSources& sources, std::string colorInput,
                         PresentBackground background, std::string depthInput)
    : colorInput_(std::move(colorInput)),
      background_(background),
      depthInput_(std::move(depthInput)),
      stages_(sources, "render/Present.comp", {variantFor(background)}) {}

std::vector<std::string_view> PresentPass::inputs(const RenderSettings&) const {
    if (background_ != PresentBackground::WhereNoDepth) {
        return {colorInput_};
    }
    return {colorInput_, depthInput_};
}

void PresentPass::execute(FrameContext& frame) {
    const glm::ivec2 size = frame.outputSize();
    Texture& image = frame.resources.ensureTexture("image", TextureFormat::RGBA8, size.x, size.y);
    const bool whole = background_ == PresentBackground::InColor || !frame.restricted();
    if (!whole) {
        clearToBackground(frame, image);
    }
    frame.resources.texture(colorInput_).bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    if (background_ == PresentBackground::WhereNoDepth) {
        frame.resources.texture(depthInput_).bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    }
    image.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    glProgramUniform1i(stages_[0].id(), SUBSCAN_UNIFORM_DIVISOR, frame.divisor);
    if (whole) {
        stages_.runOverImage(0, size.x, size.y);
    } else {
        stages_.runOverRegion(0, outputRegion(frame));
    }
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
