#pragma once

#include <string>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// The final picture "image": the linear colour input encoded to sRGB 8-bit. When a depth input
/// is named, pixels where it is +inf show the background, and a frame restricted to the points'
/// bounds is encoded only there (the rest is cleared to the background).
class PresentPass final : public RenderPass {
  public:
    PresentPass(const ShaderSources& sources, std::string colorInput, std::string depthInput);

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
    std::string depthInput_;
    ComputeStages stages_;
};

}  // namespace subscan
