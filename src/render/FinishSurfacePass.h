#pragma once

#include <map>
#include <tuple>

#include "gpu/GlObjects.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

class TemporalHistory;

/// The full-resolution end of the surface mode in one dispatch (LevelZero::Fused): per pixel the
/// push's level 0, the fill-removal mask, the blended normal, the shading and the sRGB encoding
/// over the background, from the pyramids PullPushPass, FillRemovalPass and NormalsPass leave
/// above level 0. Writes "image" and "surfaceDepth" (+inf off the surface) and nothing between:
/// on llvmpipe the per-pass chain's six full-screen images cost more than their arithmetic.
/// When the normals follow the surface to the outline (followsNormalsToOutline), which needs
/// the mask around each pixel, the mask comes from FillRemovalPass's "surfaceDepth" instead.
/// Equals the chain up to its half-float rounding of colour, normals and radiance. With the
/// temporal filter it also blends the frame into the history when the filter restarts or the
/// camera rests (Output::Temporal: TemporalPass's work without its dispatch), or leaves
/// "radianceAndDepth" for a TemporalPass after it (Output::RadianceAndDepth, RGBA32F: linear
/// radiance, the depth in alpha, so that the pass loads each neighbour once; a moving camera's
/// blend needs the neighbourhood, which here would take a work-group barrier that made the
/// pass 14 ms slower on llvmpipe).
class FinishSurfacePass final : public RenderPass {
  public:
    enum class Output { Picture, RadianceAndDepth, Temporal };

    /// `history` is the filter's memory, for Output::Temporal.
    FinishSurfacePass(const ShaderSources& sources, Output output,
                      TemporalHistory* history = nullptr);

    std::string_view name() const override { return "FinishSurface"; }
    std::vector<std::string_view> inputs(const RenderSettings& settings) const override;
    std::vector<std::string_view> outputs(const RenderSettings& settings) const override;
    void execute(FrameContext& frame) override;

    /// Whether a frame can finish here: at full resolution (reduced frames scale up in
    /// Present) with a pyramid level above level 0 (a one-pixel image has none).
    static bool canFinish(int divisor, const gpu::PyramidLayout& pyramid) {
        return divisor == 1 && pyramid.info.x >= 2;
    }

  private:
    /// Directional lights or not, FINISH_OUTPUT, and whether the mask comes from
    /// "surfaceDepth" (FINISH_SEES_OUTLINE).
    using Variant = std::tuple<bool, int, bool>;

    /// The shader of a variant, built on first use: on llvmpipe an unused loop over
    /// directional lights still costs a frame lit by the head light alone a sixth of this pass.
    const Program& program(const Variant& variant);

    const ShaderSources& sources_;
    Output output_;
    TemporalHistory* history_;
    std::map<Variant, Program> programs_;
    UniformBlock<gpu::ShadeParams> params_{"FinishSurface.shade"};
};

}  // namespace subscan
