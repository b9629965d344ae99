#pragma once

#include <string>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Where the background shows in Present's colour input.
enum class PresentBackground {
    InColor,       // the colour already holds it
    WhereNoDepth,  // where the depth input is +inf
    ByCoverage,    // under the colour's alpha, the share of the pixel the surface covers
                   // (OutlineCoveragePass)
};

/// The final picture "image": the linear colour input over the background, encoded to sRGB
/// 8-bit. Unless the colour holds the background, a frame restricted to the points' bounds is
/// encoded only there (the rest is cleared to the background).
class PresentPass final : public RenderPass {
  public:
    /// `depthInput` names the depth image for PresentBackground::WhereNoDepth.
    PresentPass(const ShaderSources& sources, std::string colorInput, PresentBackground background,
                std::string depthInput = {});

    std::string_view name() const override { return "Present"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"image"};
    }
    void execute(FrameContext& frame) override;

    /// Fills `image` with the frame's background exactly as the shader encodes it.
    static void clearToBackground(const FrameContext& frame, Texture& image);

  private:
    std::string colorInput_;
    PresentBackground background_;
    std::string depthInput_;
    ComputeStages stages_;
};

}  // namespace subscan
