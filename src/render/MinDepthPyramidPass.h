#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// The min-depth pyramid of the rasterized depth (paper Fig. 3), every level in the buffer
/// "pyramid" (see PyramidLayout), and where each texel's points lie ("pointCentroids", for
/// fill removal), and with the local spacing the spacing ratio of each texel's nearest point
/// ("frontSpacing", for hidden point removal). Where surfaceBoundsAllowed(), it also measures
/// the bounds of the rasterized
/// points, and of the pixels beyond them that the fill may keep for a sparse surface, into
/// FrameContext::pointBounds for the passes after it.
class MinDepthPyramidPass final : public RenderPass {
  public:
    explicit MinDepthPyramidPass(const ShaderSources& sources);

    std::string_view name() const override { return "MinDepthPyramid"; }
    std::vector<std::string_view> inputs(const RenderSettings& settings) const override {
        if (settings.surface.localSpacing) {
            return {"depth", "color"};
        }
        return {"depth"};
    }
    std::vector<std::string_view> outputs(const RenderSettings& settings) const override {
        if (settings.surface.localSpacing) {
            return {"pyramid", "pointCentroids", "frontSpacing"};
        }
        return {"pyramid", "pointCentroids"};
    }
    void execute(FrameContext& frame) override;

  private:
    enum Stage { First, Reduce, Bounds };
    glm::ivec4 measureBounds(const FrameContext& frame);

    ComputeStages stages_;
    Buffer bounds_;
};

}  // namespace subscan
