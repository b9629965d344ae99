#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Separates surface from filled background (DESIGN.md §5.4, "fill removal"): "mask" is 1 where
/// the pull weight on the level of the expected point gap reaches the threshold, and
/// "surfaceDepth" holds the filled depth there (+inf elsewhere).
class FillRemovalPass final : public RenderPass {
  public:
    explicit FillRemovalPass(const ShaderSources& sources);

    std::string_view name() const override { return "FillRemoval"; }
    std::vector<std::string_view> inputs() const override { return {"filledDepth", "pullWeights"}; }
    std::vector<std::string_view> outputs() const override { return {"mask", "surfaceDepth"}; }
    void execute(FrameContext& frame) override;

  private:
    ComputeStages stages_;
};

}  // namespace subscan
