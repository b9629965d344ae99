#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Hidden point removal on the min-depth pyramid (DESIGN.md §5.3): "visibility" is 1 where a
/// rasterized point is visible, 0 where it is hidden or there is none. "color"'s alpha is the
/// point's local spacing ratio, which shrinks its search radius where below 1; with the local
/// spacing, a nearer texel's "frontSpacing" widens it to span two of that occluder's gaps.
class HiddenPointRemovalPass final : public RenderPass {
  public:
    explicit HiddenPointRemovalPass(const ShaderSources& sources);

    std::string_view name() const override { return "HiddenPointRemoval"; }
    std::vector<std::string_view> inputs(const RenderSettings& settings) const override {
        if (settings.surface.localSpacing) {
            return {"pyramid", "color", "frontSpacing"};
        }
        return {"pyramid", "color"};
    }
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"visibility"};
    }
    void execute(FrameContext& frame) override;

  private:
    ComputeStages stages_;
};

}  // namespace subscan
