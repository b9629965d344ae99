#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Separates surface from filled background (DESIGN.md §5.4, "fill removal"): "mask" is 1 where
/// visible points surround the pixel up to the level of the expected point gap (looked up in
/// the per-direction "fillReach" pyramid), and "surfaceDepth" holds the filled depth there
/// (+inf elsewhere).
class FillRemovalPass final : public RenderPass {
  public:
    explicit FillRemovalPass(const ShaderSources& sources);

    std::string_view name() const override { return "FillRemoval"; }
    std::vector<std::string_view> inputs() const override { return {"filledDepth", "pullWeights"}; }
    std::vector<std::string_view> outputs() const override {
        return {"fillReach", "mask", "surfaceDepth"};
    }
    void execute(FrameContext& frame) override;

  private:
    enum Stage { Reach, Mask };
    ComputeStages stages_;
};

}  // namespace subscan
