#include "render/ShadePass.h"

#include <algorithm>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/Error.h"

#include "render/LightMaps.h"
#include "sss/MaterialLibrary.h"
#include "sss/ProfileFit.h"

namespace subscan {

ShadePass::ShadePass(const ShaderSources& sources, ShadeOutputs outputs)
    : outputs_(outputs),
      stages_(sources, "render/Shade.comp",
              {outputs == ShadeOutputs::Split ? "SPLIT" : "RADIANCE"}) {}

std::vector<std::string_view> ShadePass::outputs(const RenderSettings&) const {
    if (outputs_ == ShadeOutputs::Split) {
        return {"diffuse", "specular", "albedo", "radiance"};
    }
    return {"radiance"};
}

namespace {

static_assert(kMaxFittedGaussians <= SUBSCAN_MAX_PROFILE_GAUSSIANS,
              "every fitted profile must fit the shading's transmission");

/// The material's diffusion profile in scene units, for light through thin parts; its
/// zero-variance terms (a delta) transmit nothing through any thickness.
void setTransmissionProfile(gpu::ShadeParams& params, const ScatteringSettings& settings) {
    const double unitsPerMm = settings.scale / millimetresPerUnit(settings.unit);
    std::uint32_t count = 0;
    for (const Gaussian& term : findMaterial(settings.material).gaussians.gaussians) {
        const double variance = term.varianceMm2 * unitsPerMm * unitsPerMm;
        if (variance > 0.0) {
            if (count == SUBSCAN_MAX_PROFILE_GAUSSIANS) {
                throw Error(fmt::format("the material '{}' has more than {} Gaussians to transmit",
                                        settings.material, SUBSCAN_MAX_PROFILE_GAUSSIANS));
            }
            params.profile[count++] = {term.weight[0], term.weight[1], term.weight[2], variance};
        }
    }
    params.profileCount = {count, 0, 0, 0};
}

}  // namespace

gpu::ShadeParams ShadePass::parameters(const FrameContext& frame) {
    const ShadingSettings& settings = frame.settings.shading;
    const Camera& camera = frame.camera;
    gpu::ShadeParams params{};
    params.headLight = glm::vec4(settings.headLight, 0.0f);
    params.ambient = glm::vec4(settings.ambient, 0.0f);
    params.specular = {settings.specular, settings.shininess, 0.0f, 0.0f};
    const std::size_t count = std::min<std::size_t>(settings.lights.size(), SUBSCAN_MAX_LIGHTS);
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 direction = glm::dvec3(
            camera.view * glm::dvec4(towardsLightInWorld(settings.lights[i], camera.view), 0.0));
        params.lightDirection[i] = glm::vec4(glm::normalize(direction), 0.0);
        params.lightColor[i] = glm::vec4(settings.lights[i].radiance, 0.0f);
    }
    params.lightCount = {static_cast<std::uint32_t>(count), 0, 0, 0};
    if (frame.lightMaps != nullptr) {
        frame.lightMaps->prepareShading(params, camera, settings, frame.spacing);
        if (transmitsLight(frame.settings)) {
            setTransmissionProfile(params, frame.settings.scattering);
        }
    }
    return params;
}

void ShadePass::execute(FrameContext& frame) {
    FrameResources& resources = frame.resources;
    const int width = frame.width();
    const int height = frame.height();
    // The other outputs are read only on the surface; the radiance is exported whole.
    Texture& radiance = frame.imageOverRegion("radiance", TextureFormat::RGBA16F);
    params_.set(parameters(frame));
    params_.bind(SUBSCAN_UBO_PASS);
    resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    resources.texture("normals").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    resources.texture("filledColor").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    if (outputs_ == ShadeOutputs::Split) {
        resources.ensureTexture("diffuse", TextureFormat::RGBA16F, width, height)
            .bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
        resources.ensureTexture("specular", TextureFormat::RGBA16F, width, height)
            .bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
        resources.ensureTexture("albedo", TextureFormat::RGBA16F, width, height)
            .bindImage(SUBSCAN_IMAGE_OUT2, GL_WRITE_ONLY);
    }
    radiance.bindImage(SUBSCAN_IMAGE_OUT3, GL_WRITE_ONLY);
    stages_.runOverRegion(0, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
