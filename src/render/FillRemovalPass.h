#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Separates surface from filled background (DESIGN.md §5.4, "fill removal"; beyond it, the
/// sub-pixel outline of SurfaceSettings::subpixelOutline): "mask" is 1 where points surround
/// the pixel up to the level of the expected point gap (visible ones beside it, hidden ones too
/// from level 1 on; looked up in the per-direction "fillReach" pyramid), on the sub-pixel
/// outline the share of the pixel the surface covers (above a half; OutlineCoveragePass), 0
/// elsewhere, and "surfaceDepth" holds the filled depth where it is not 0 (+inf elsewhere). A
/// direction counts only where the texel's points lie in it as seen from the pixel (their mean,
/// "pointCentroids"), so the fill stays within the points' convex hull; that walk, and the reach
/// beyond a sparse surface's outermost points, run per level-1 texel ("fillSparse"). With
/// LevelZero::Fused only "fillReach" above level 0, and "mask" and "surfaceDepth" when the normals
/// follow the surface to the outline (FinishSurface then reads them).
class FillRemovalPass final : public RenderPass {
  public:
    explicit FillRemovalPass(const ShaderSources& sources);

    std::string_view name() const override { return "FillRemoval"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override;
    void execute(FrameContext& frame) override;
    void setLevelZero(LevelZero levelZero) { levelZero_ = levelZero; }

  private:
    enum Stage { Reach, Mask, SurfaceDepth };
    ComputeStages stages_;
    LevelZero levelZero_ = LevelZero::PerPass;
};

}  // namespace subscan
