#include "render/OutlineCoveragePass.h"

namespace subscan {

OutlineCoveragePass::OutlineCoveragePass(const ShaderSources& sources, std::string colorInput)
    : colorInput_(std::move(colorInput)),
      stages_(sources, "render/OutlineCoverage.comp", {"ALL"}) {}

std::vector<std::string_view> OutlineCoveragePass::inputs(const RenderSettings&) const {
    return {colorInput_, "mask"};
}

void OutlineCoveragePass::execute(FrameContext& frame) {
    frame.resources.texture("mask").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    frame.resources.texture(colorInput_).bindImage(SUBSCAN_IMAGE_OUT0, GL_READ_WRITE);
    stages_.runOverRegion(0, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
