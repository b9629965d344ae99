#include "render/SingleScatteringPass.h"

#include "render/ShadePass.h"
#include "sss/Dipole.h"
#include "sss/MaterialLibrary.h"

namespace subscan {

namespace {

glm::vec4 rgbVector(const Rgb& value) {
    return {static_cast<float>(value[0]), static_cast<float>(value[1]),
            static_cast<float>(value[2]), 0.0f};
}

enum LightStage { HeadLight, MarchedLights, MappedLights };

std::vector<std::string> stageNames(SingleScatteringBase base) {
    const std::string prefix = base == SingleScatteringBase::Radiance ? "RADIANCE" : "SCATTERED";
    return {prefix + "_HEAD_LIGHT", prefix + "_LIGHTS", prefix + "_LIGHT_MAPS"};
}

}  // namespace

SingleScatteringPass::SingleScatteringPass(const ShaderSources& sources, SingleScatteringBase base)
    : base_(base), stages_(sources, "render/SingleScattering.comp", stageNames(base)) {}

std::vector<std::string_view> SingleScatteringPass::inputs(const RenderSettings&) const {
    return {"surfaceDepth", "normals", "albedo",
            base_ == SingleScatteringBase::Radiance ? "radiance" : "scatteredRadiance"};
}

gpu::SingleScatterParams SingleScatteringPass::parameters(const ScatteringSettings& settings) {
    checkScatteringSettings(settings);
    gpu::SingleScatterParams params{};
    if (settings.coefficients == CoefficientSource::Material) {
        const Material& material = measuredMaterial(settings.material);
        params.sigmaSPrime = rgbVector(*material.sigmaSPrime);
        params.sigmaA = rgbVector(*material.sigmaA);
    }
    params.meanFreePath = glm::vec4(settings.meanFreePathMm, 0.0f);
    params.medium = {static_cast<float>(scatteringEta(settings)), settings.phaseG,
                     static_cast<float>(millimetresPerUnit(settings.unit) / settings.scale), 0.0f};
    params.sampling = {static_cast<float>(settings.singleSamples),
                       static_cast<float>(kTableEntries),
                       static_cast<float>(ReducedAlbedoTable::kMaxReflectance),
                       static_cast<float>(kMaxMarchSteps)};
    params.flags = {settings.coefficients == CoefficientSource::Color ? 1u : 0u, 1u, 0u, 0u};
    return params;
}

void SingleScatteringPass::execute(FrameContext& frame) {
    const ScatteringSettings& settings = frame.settings.scattering;
    gpu::SingleScatterParams params = parameters(settings);
    params.flags.y = frame.outputs == FrameOutputs::Everything ? 1u : 0u;
    const double eta = params.medium.x;
    if (tableEta_ != eta) {
        const std::vector<float> roots =
            reducedAlbedoRootTable(ReducedAlbedoTable(eta), kTableEntries);
        albedoRoots_ = Buffer::fromSpan(std::span<const float>(roots), "SingleScattering.roots");
        tableEta_ = eta;
    }
    FrameResources& resources = frame.resources;
    const int width = frame.width();
    const int height = frame.height();
    Texture& single =
        resources.ensureTexture("singleScattering", TextureFormat::RGBA16F, width, height);
    // Full floats: the material's coefficients come out exactly as given.
    Texture& sigmaSPrime =
        resources.ensureTexture("sigmaSPrime", TextureFormat::RGBA32F, width, height);
    Texture& sigmaA = resources.ensureTexture("sigmaA", TextureFormat::RGBA32F, width, height);
    Texture& scattered =
        base_ == SingleScatteringBase::Radiance
            ? resources.ensureTexture("scatteredRadiance", TextureFormat::RGBA16F, width, height)
            : resources.texture("scatteredRadiance");
    if (frame.restricted() && frame.outputs == FrameOutputs::Everything) {
        // Exported whole; the pass writes only the points' region.
        frame.clear(single);
        frame.clear(sigmaSPrime);
        frame.clear(sigmaA);
    }
    if (frame.restricted() && base_ == SingleScatteringBase::Radiance) {
        frame.clear(scattered);
    }
    params_.set(params);
    params_.bind(SUBSCAN_UBO_PASS);
    const gpu::ShadeParams lights = ShadePass::parameters(frame);
    lights_.set(lights);
    lights_.bind(SUBSCAN_UBO_LIGHTS);
    albedoRoots_.bindTexels(SUBSCAN_TEXELS_ALBEDO_ROOTS, TextureFormat::R32F);
    resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    resources.texture("normals").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    resources.texture("albedo").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    if (base_ == SingleScatteringBase::Radiance) {
        resources.texture("radiance").bindImage(SUBSCAN_IMAGE_IN3, GL_READ_ONLY);
        scattered.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    } else {
        scattered.bindImage(SUBSCAN_IMAGE_OUT0, GL_READ_WRITE);
    }
    single.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    sigmaSPrime.bindImage(SUBSCAN_IMAGE_OUT2, GL_WRITE_ONLY);
    sigmaA.bindImage(SUBSCAN_IMAGE_OUT3, GL_WRITE_ONLY);
    const LightStage stage =
        lights.lightCount.x == 0                                                  ? HeadLight
        : frame.lightMaps != nullptr && settings.lightPath == LightPath::LightMap ? MappedLights
                                                                                  : MarchedLights;
    stages_.runOverRegion(stage, frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
