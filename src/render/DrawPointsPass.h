#pragma once

#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// The baselines common viewers show, drawn with the fixed-function pipeline: GL_POINTS of
/// 1 pixel ("points-gl") or square splats of `pointSize` pixels ("splats") with a depth test.
/// Writes "depth" and "color" exactly like RasterizePoints, so the same later passes apply.
class DrawPointsPass final : public RenderPass {
  public:
    explicit DrawPointsPass(const ShaderSources& sources);

    std::string_view name() const override { return "DrawPoints"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override { return {}; }
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"depth", "color"};
    }
    void execute(FrameContext& frame) override;

  private:
    Program program_;
    VertexArray vertexArray_;
    UniformBlock<gpu::DrawParams> params_{"DrawPoints.params"};
    Texture depthTest_;
    Framebuffer framebuffer_;
    GLuint attachedColor_ = 0;
    GLuint attachedDepth_ = 0;
};

}  // namespace subscan
