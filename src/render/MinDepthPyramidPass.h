#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// The min-depth pyramid of the rasterized depth (paper Fig. 3), every level in the buffer
/// "pyramid" (see PyramidLayout).
class MinDepthPyramidPass final : public RenderPass {
  public:
    explicit MinDepthPyramidPass(const ShaderSources& sources);

    std::string_view name() const override { return "MinDepthPyramid"; }
    std::vector<std::string_view> inputs() const override { return {"depth"}; }
    std::vector<std::string_view> outputs() const override { return {"pyramid"}; }
    void execute(FrameContext& frame) override;

  private:
    enum Stage { Copy, Reduce };
    ComputeStages stages_;
};

}  // namespace subscan
