#include "render/HiddenPointRemovalPass.h"

namespace subscan {

HiddenPointRemovalPass::HiddenPointRemovalPass(const ShaderSources& sources)
    : stages_(sources, "render/HiddenPointRemoval.comp", {"ALL"}) {}

void HiddenPointRemovalPass::execute(FrameContext& frame) {
    Texture& visibility = frame.resources.ensureTexture("visibility", TextureFormat::R8,
                                                        frame.width(), frame.height());
    frame.resources.buffer("pyramid").bindTexels(SUBSCAN_TEXELS_PYRAMID, TextureFormat::R32F);
    frame.resources.texture("color").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    if (frame.settings.surface.localSpacing) {
        frame.resources.buffer("frontSpacing")
            .bindTexels(SUBSCAN_TEXELS_FRONT_SPACING, TextureFormat::R32F);
    }
    visibility.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    stages_.runOverRegion(0, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
