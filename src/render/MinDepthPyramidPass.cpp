#include "render/MinDepthPyramidPass.h"

#include "render/Pyramid.h"

namespace subscan {

MinDepthPyramidPass::MinDepthPyramidPass(const ShaderSources& sources)
    : stages_(sources, "render/MinDepthPyramid.comp", {"COPY", "REDUCE"}) {}

void MinDepthPyramidPass::execute(FrameContext& frame) {
    Buffer& pyramid =
        frame.resources.ensureBuffer("pyramid", pyramidTexels(frame.pyramid) * sizeof(float));
    pyramid.bindStorage(SUBSCAN_SSBO_PYRAMID);
    frame.resources.texture("depth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    stages_.runOverImage(Copy, frame.width(), frame.height());
    for (unsigned level = 1; level < frame.pyramid.info.x; ++level) {
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        const auto& size = frame.pyramid.levels[level];
        stages_.runOverImage(Reduce, static_cast<int>(size.y), static_cast<int>(size.z), level);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

}  // namespace subscan
