#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Normals of the reconstructed surface (DESIGN.md §5.5): per push level from 1 into the buffer
/// "normalPyramid", then blended per pixel between the two levels around its smoothing level
/// into "normals" (view space, zero outside the mask) unless LevelZero::Fused.
class NormalsPass final : public RenderPass {
  public:
    explicit NormalsPass(const ShaderSources& sources);

    std::string_view name() const override { return "Normals"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override;
    void execute(FrameContext& frame) override;
    void setLevelZero(LevelZero levelZero) { levelZero_ = levelZero; }

  private:
    enum Stage { Level, Blend };
    ComputeStages stages_;
    LevelZero levelZero_ = LevelZero::PerPass;
};

}  // namespace subscan
