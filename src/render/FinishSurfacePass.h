#pragma once

#include <optional>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// The full-resolution end of the surface mode in one dispatch (LevelZero::Fused): per pixel the
/// push's level 0, the fill-removal mask, the blended normal, the shading and the sRGB encoding
/// over the background, from the pyramids PullPushPass, FillRemovalPass and NormalsPass leave
/// above level 0. Writes "image" and "surfaceDepth" (+inf off the surface) and nothing between:
/// on llvmpipe the per-pass chain's six full-screen images cost more than their arithmetic.
/// Equals the chain up to its half-float rounding of colour, normals and radiance. For the
/// temporal filter it writes the linear "radiance" (+ "surfaceDepth") instead of the picture.
class FinishSurfacePass final : public RenderPass {
  public:
    enum class Output { Picture, Radiance };

    FinishSurfacePass(const ShaderSources& sources, Output output);

    std::string_view name() const override { return "FinishSurface"; }
    std::vector<std::string_view> inputs() const override {
        return {"pullValues", "pullWeights", "pushValues", "fillReach", "normalPyramid"};
    }
    std::vector<std::string_view> outputs() const override {
        return {output_ == Output::Picture ? "image" : "radiance", "surfaceDepth"};
    }
    void execute(FrameContext& frame) override;

    /// Whether a frame can finish here: at full resolution (reduced frames scale up in
    /// Present) with a pyramid level above level 0 (a one-pixel image has none).
    static bool canFinish(int divisor, const gpu::PyramidLayout& pyramid) {
        return divisor == 1 && pyramid.info.x >= 2;
    }

  private:
    /// Built on first use, with or without the loop over directional lights: on llvmpipe that
    /// loop costs a frame lit by the head light alone a sixth of this pass even when it runs
    /// zero times.
    const ComputeStages& stagesFor(bool directionalLights);

    const ShaderSources& sources_;
    Output output_;
    std::optional<ComputeStages> headLightOnly_;
    std::optional<ComputeStages> withLights_;
    UniformBlock<gpu::ShadeParams> params_{"FinishSurface.shade"};
};

}  // namespace subscan
