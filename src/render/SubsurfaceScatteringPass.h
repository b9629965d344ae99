#pragma once

#include <array>
#include <vector>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"
#include "sss/GaussianSet.h"

namespace subscan {

/// Screen-space subsurface scattering (DESIGN.md §6.1): the diffuse light of the shaded
/// surface blurred by each Gaussian of the material's diffusion profile (a horizontal and a
/// vertical pass each, taps weighted by their 3-D distance on the surface), summed with RGB
/// weights, the albedo placed before, after or on both sides of the blur, specular added after.
/// Writes "scatteredRadiance" (zero outside the surface, like "radiance").
class SubsurfaceScatteringPass final : public RenderPass {
  public:
    explicit SubsurfaceScatteringPass(const ShaderSources& sources);

    std::string_view name() const override { return "SubsurfaceScattering"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override {
        return {"surfaceDepth", "diffuse", "specular", "albedo"};
    }
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"sssSource", "sssHalf", "sssBlurred", "sssSum", "scatteredRadiance"};
    }
    void execute(FrameContext& frame) override;

    /// One Gaussian of the profile as the GPU blurs it.
    struct BlurStep {
        double sigma = 0.0;  // standard deviation of this blur, scene units
        std::array<float, 3> weight{};
        bool fromPrevious = false;  // blurs the previous step's result (cumulative sets)
    };
    struct BlurChain {
        std::array<float, 3> unblurredWeight{};  // of the terms with zero variance
        std::vector<BlurStep> steps;
    };
    /// The blurs for `set` with every radius multiplied by `scale`, in a scene whose unit is
    /// `millimetresPerUnit` mm.
    static BlurChain blurChain(const GaussianSet& set, double scale, double millimetresPerUnit);

  private:
    enum Stage { Prepare, Blur, BlurAccumulate, Combine };
    ComputeStages stages_;
    UniformBlock<gpu::ScatterParams> params_{"SubsurfaceScattering.params"};
};

}  // namespace subscan
