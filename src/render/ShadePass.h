#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// Deferred shading of the reconstructed surface (DESIGN.md §5.6): Lambert + Blinn-Phong under
/// a head light and optional directional lights, plus ambient. Writes "diffuse", "specular",
/// "albedo" (kept apart for subsurface scattering) and their sum "radiance".
class ShadePass final : public RenderPass {
  public:
    explicit ShadePass(const ShaderSources& sources);

    std::string_view name() const override { return "Shade"; }
    std::vector<std::string_view> inputs() const override {
        return {"surfaceDepth", "normals", "filledColor"};
    }
    std::vector<std::string_view> outputs() const override {
        return {"diffuse", "specular", "albedo", "radiance"};
    }
    void execute(FrameContext& frame) override;

    /// The shader's parameters for these settings and camera (directions into view space).
    static gpu::ShadeParams parameters(const ShadingSettings& settings, const Camera& camera);

  private:
    ComputeStages stages_;
    UniformBlock<gpu::ShadeParams> params_{"Shade.params"};
};

}  // namespace subscan
