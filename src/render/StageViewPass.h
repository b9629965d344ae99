#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Turns one intermediate of the surface pipeline into the picture "stage" (linear RGB,
/// background included) for `--stage` and the viewer (the panels of the paper's Figure 2).
class StageViewPass final : public RenderPass {
  public:
    /// `stage` is one of Depth, Pyramid, Visibility, Pull, Push, Fill, Normals.
    StageViewPass(const ShaderSources& sources, Stage stage);

    std::string_view name() const override { return "StageView"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"stage"};
    }
    void execute(FrameContext& frame) override;

  private:
    Stage stage_;
    ComputeStages stages_;
};

}  // namespace subscan
