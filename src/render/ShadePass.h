#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// Deferred shading of the reconstructed surface (DESIGN.md §5.6): Lambert + Blinn-Phong under
/// a head light and optional directional lights, plus ambient. Writes "radiance", and with
/// ShadeOutputs::Split also its parts "diffuse", "specular" and "albedo" for subsurface
/// scattering (three more full-screen writes that the surface mode does not need).
enum class ShadeOutputs { Radiance, Split };

class ShadePass final : public RenderPass {
  public:
    ShadePass(const ShaderSources& sources, ShadeOutputs outputs);

    std::string_view name() const override { return "Shade"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override {
        return {"surfaceDepth", "normals", "filledColor"};
    }
    std::vector<std::string_view> outputs(const RenderSettings&) const override;
    void execute(FrameContext& frame) override;

    /// The shader's parameters for the frame's settings and camera (directions into view
    /// space); with the frame's light maps, also their shadow parameters, and the maps bound.
    static gpu::ShadeParams parameters(const FrameContext& frame);

  private:
    ShadeOutputs outputs_;
    ComputeStages stages_;
    UniformBlock<gpu::ShadeParams> params_{"Shade.params"};
};

}  // namespace subscan
