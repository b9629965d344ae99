#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// Pull-push fill of depth and colour from the visible points (DESIGN.md §5.4). Keeps every
/// pull level ("pullValues" w*(depth, rgb), "pullWeights" w and w * local spacing ratio) and
/// push level from 1 up ("pushValues"); level 0 of the push is "filledDepth" and "filledColor"
/// (LevelZero::PerPass).
class PullPushPass final : public RenderPass {
  public:
    explicit PullPushPass(const ShaderSources& sources);

    std::string_view name() const override { return "PullPush"; }
    std::vector<std::string_view> inputs(const RenderSettings& settings) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override;
    void execute(FrameContext& frame) override;
    void setLevelZero(LevelZero levelZero) { levelZero_ = levelZero; }

  private:
    enum Stage { PullInit, Pull, PushTop, Push };
    ComputeStages stages_;
    LevelZero levelZero_ = LevelZero::PerPass;
};

}  // namespace subscan
