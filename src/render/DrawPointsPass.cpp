#include "render/DrawPointsPass.h"

#include <array>
#include <limits>

namespace subscan {

DrawPointsPass::DrawPointsPass(const ShaderSources& sources)
    : program_(Program::graphics(sources, "render/DrawPoints.vert", "render/DrawPoints.frag")) {
    const GLuint vao = vertexArray_.id();
    glEnableVertexArrayAttrib(vao, SUBSCAN_ATTRIBUTE_POSITION);
    glVertexArrayAttribFormat(vao, SUBSCAN_ATTRIBUTE_POSITION, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, SUBSCAN_ATTRIBUTE_POSITION, 0);
    glEnableVertexArrayAttrib(vao, SUBSCAN_ATTRIBUTE_COLOR);
    glVertexArrayAttribFormat(vao, SUBSCAN_ATTRIBUTE_COLOR, 4, GL_UNSIGNED_BYTE, GL_TRUE, 0);
    glVertexArrayAttribBinding(vao, SUBSCAN_ATTRIBUTE_COLOR, 1);
}

void DrawPointsPass::execute(FrameContext& frame) {
    const int width = frame.camera.width;
    const int height = frame.camera.height;
    Texture& depth = frame.resources.ensureTexture("depth", TextureFormat::R32F, width, height);
    Texture& color = frame.resources.ensureTexture("color", TextureFormat::RGBA16F, width, height);
    if (depthTest_.width() != width || depthTest_.height() != height || !depthTest_.id()) {
        depthTest_ = Texture(TextureFormat::Depth32F, width, height, "DrawPoints.depthTest");
    }
    if (attachedColor_ != color.id() || attachedDepth_ != depthTest_.id()) {
        const std::array<const Texture*, 2> targets{&color, &depth};
        framebuffer_ = Framebuffer(targets, &depthTest_, "DrawPoints");
        attachedColor_ = color.id();
        attachedDepth_ = depthTest_.id();
    }

    const GLuint fbo = framebuffer_.id();
    const float transparent[4] = {0, 0, 0, 0};
    const float infinity[4] = {std::numeric_limits<float>::infinity(), 0, 0, 0};
    const float farthest = 1.0f;
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, transparent);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 1, infinity);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &farthest);

    const bool splats = frame.settings.raster.mode == RenderMode::Splats;
    params_.set({glm::vec4(splats ? frame.settings.raster.pointSize : 1.0f, 0, 0, 0)});
    params_.bind(SUBSCAN_UBO_PASS);

    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, width, height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_PROGRAM_POINT_SIZE);
    program_.use();
    glBindVertexArray(vertexArray_.id());
    for (const GpuPointCloud::Chunk& chunk : frame.cloud.chunks()) {
        glVertexArrayVertexBuffer(vertexArray_.id(), 0, chunk.positions.id(), 0, 3 * sizeof(float));
        glVertexArrayVertexBuffer(vertexArray_.id(), 1, chunk.colors.id(), 0,
                                  sizeof(std::uint32_t));
        glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(chunk.pointCount));
    }
    // Detached, so that the vertex array does not keep a replaced cloud's buffers (and, where
    // they borrow it, its memory) alive (Renderer::replaceCloud).
    glVertexArrayVertexBuffer(vertexArray_.id(), 0, 0, 0, 3 * sizeof(float));
    glVertexArrayVertexBuffer(vertexArray_.id(), 1, 0, 0, sizeof(std::uint32_t));
    glBindVertexArray(0);
    glDisable(GL_PROGRAM_POINT_SIZE);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

}  // namespace subscan
