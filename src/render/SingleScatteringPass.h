#pragma once

#include <optional>

#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// What single scattering is added to: the shaded surface's "radiance" (diffuse + specular;
/// scattering method `single`), or "scatteredRadiance" after the Gaussian blur (`both`).
enum class SingleScatteringBase { Radiance, Scattered };

/// Single scattering in screen space (DESIGN.md §6.3, §6.4): per surface pixel, samples along
/// the refracted view ray, a march through the reconstructed depth towards each light (the head
/// light and every directional light) to where it entered, and the single-scattered radiance
/// added to the base. σs′ and σa come from the material or per pixel from the colour. Writes
/// "scatteredRadiance", "singleScattering" (that term alone) and "sigmaSPrime"/"sigmaA"
/// (mm⁻¹ per pixel); all zero outside the surface.
class SingleScatteringPass final : public RenderPass {
  public:
    SingleScatteringPass(const ShaderSources& sources, SingleScatteringBase base);

    std::string_view name() const override { return "SingleScattering"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return {"scatteredRadiance", "singleScattering", "sigmaSPrime", "sigmaA"};
    }
    void execute(FrameContext& frame) override;

    /// Entries of the table that inverts R_d on the GPU (at least 1024, DESIGN.md §6.4).
    static constexpr std::size_t kTableEntries = 4096;
    /// Most march steps towards a light (about one pixel each until then).
    static constexpr int kMaxMarchSteps = 32;

    /// The shader's parameters; throws subscan::Error when the settings ask for a material's
    /// coefficients and the material has none.
    static gpu::SingleScatterParams parameters(const ScatteringSettings& settings);

  private:
    SingleScatteringBase base_;
    ComputeStages stages_;
    UniformBlock<gpu::SingleScatterParams> params_{"SingleScattering.params"};
    UniformBlock<gpu::ShadeParams> lights_{"SingleScattering.lights"};
    std::optional<double> tableEta_;  // the η the table below was built for
    Buffer albedoRoots_;
};

}  // namespace subscan
