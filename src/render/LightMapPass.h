#pragma once

#include "render/ComputeStages.h"
#include "render/RenderPass.h"

namespace subscan {

/// The last step of a light's view (LightMaps): its reconstructed "surfaceDepth" and "normals"
/// packed into one RGBA32F image "lightMap" — depth along the light (+inf where the light meets
/// nothing) and the surface's normal in the light's view space — which shading (shadows) and
/// single scattering (entries hidden from the camera) read as one texture per light.
class LightMapPass final : public RenderPass {
  public:
    explicit LightMapPass(const ShaderSources& sources);

    std::string_view name() const override { return "LightMap"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override {
        return {"surfaceDepth", "normals"};
    }
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"lightMap"};
    }
    void execute(FrameContext& frame) override;

  private:
    ComputeStages stages_;
};

}  // namespace subscan
