#pragma once

#include <string>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// The anti-aliased outline (pipeline.md, "Anti-aliased outline"): where the sub-pixel outline
/// (SurfaceSettings::subpixelOutline) runs through a pixel of the mask, the surface covers only
/// the share of it its points' cells show, which FillRemovalPass writes into "mask". This pass
/// makes that share the alpha of the frame's final linear colour `colorInput` (after shading or
/// scattering), over which Present and the temporal filter show the background.
class OutlineCoveragePass final : public RenderPass {
  public:
    OutlineCoveragePass(const ShaderSources& sources, std::string colorInput);

    std::string_view name() const override { return "OutlineCoverage"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {colorInput_};
    }
    void execute(FrameContext& frame) override;

  private:
    std::string colorInput_;
    ComputeStages stages_;
};

}  // namespace subscan
