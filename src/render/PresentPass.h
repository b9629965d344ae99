#pragma once

#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"
#include "render/RenderPass.h"

namespace subscan {

/// The final picture: linear "color" encoded to sRGB 8-bit in "image"; pixels where "depth" is
/// +inf show the background.
class PresentPass final : public RenderPass {
  public:
    explicit PresentPass(const ShaderSources& sources);

    std::string_view name() const override { return "Present"; }
    std::vector<std::string_view> inputs() const override { return {"color", "depth"}; }
    std::vector<std::string_view> outputs() const override { return {"image"}; }
    void execute(FrameContext& frame) override;

  private:
    Program program_;
};

}  // namespace subscan
