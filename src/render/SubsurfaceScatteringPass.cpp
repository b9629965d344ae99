#include "render/SubsurfaceScatteringPass.h"

#include <algorithm>
#include <cmath>

#include "sss/MaterialLibrary.h"

namespace subscan {

namespace {

glm::vec4 weightVector(const std::array<float, 3>& weight) {
    return {weight[0], weight[1], weight[2], 0.0f};
}

}  // namespace

SubsurfaceScatteringPass::SubsurfaceScatteringPass(const ShaderSources& sources)
    : stages_(sources, "render/SubsurfaceScattering.comp",
              {"PREPARE", "BLUR", "BLUR_ACCUMULATE", "COMBINE"}) {}

SubsurfaceScatteringPass::BlurChain SubsurfaceScatteringPass::blurChain(const GaussianSet& set,
                                                                        double scale,
                                                                        double millimetresPerUnit) {
    std::vector<Gaussian> terms = set.gaussians;
    std::stable_sort(terms.begin(), terms.end(), [](const Gaussian& a, const Gaussian& b) {
        return a.varianceMm2 < b.varianceMm2;
    });
    BlurChain chain;
    double previousVariance = 0.0;  // scene units², of the last blurred term
    for (const Gaussian& term : terms) {
        const std::array<float, 3> weight{static_cast<float>(term.weight[0]),
                                          static_cast<float>(term.weight[1]),
                                          static_cast<float>(term.weight[2])};
        const double sigmaUnits = std::sqrt(term.varianceMm2) * scale / millimetresPerUnit;
        const double variance = sigmaUnits * sigmaUnits;
        if (!(variance > 0.0)) {
            for (int c = 0; c < 3; ++c) {
                chain.unblurredWeight[c] += weight[c];
            }
            continue;
        }
        BlurStep step;
        step.weight = weight;
        // A cumulative set blurs on from the previous result: Gaussians compose by adding
        // variances. Equal variances (a zero increment) repeat the previous result.
        step.fromPrevious = set.cumulative && !chain.steps.empty();
        step.sigma =
            step.fromPrevious ? std::sqrt(std::max(variance - previousVariance, 0.0)) : sigmaUnits;
        previousVariance = variance;
        chain.steps.push_back(step);
    }
    return chain;
}

void SubsurfaceScatteringPass::execute(FrameContext& frame) {
    const ScatteringSettings& settings = frame.settings.scattering;
    const BlurChain chain = blurChain(findMaterial(settings.material).gaussians, settings.scale,
                                      millimetresPerUnit(settings.unit));
    FrameResources& resources = frame.resources;
    const int width = frame.width();
    const int height = frame.height();
    auto image = [&](std::string_view name) -> Texture& {
        return resources.ensureTexture(name, TextureFormat::RGBA16F, width, height);
    };
    Texture& source = image("sssSource");
    Texture& half = image("sssHalf");
    Texture& blurred = image("sssBlurred");
    // The sum gathers one term per Gaussian: in half floats their roundings would add up.
    Texture& sum = resources.ensureTexture("sssSum", TextureFormat::RGBA32F, width, height);
    Texture& radiance = image("scatteredRadiance");
    const TexelRegion region = frame.region(0);

    gpu::ScatterParams params{};
    params.blur.y = static_cast<float>(settings.maxTaps);
    params.albedo.x = static_cast<gpu::uint>(settings.albedo);
    params.weight = weightVector(chain.unblurredWeight);
    params_.set(params);
    params_.bind(SUBSCAN_UBO_PASS);
    resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    resources.texture("diffuse").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    resources.texture("albedo").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    source.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    sum.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    stages_.runOverRegion(Prepare, region);
    glMemoryBarrier(kImageWritesBarrier);

    for (const BlurStep& step : chain.steps) {
        params.blur.x = static_cast<float>(step.sigma);
        params.blur.z = 0.0f;
        params_.set(params);
        (step.fromPrevious ? blurred : source).bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
        half.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
        stages_.runOverRegion(Blur, region);
        glMemoryBarrier(kImageWritesBarrier);

        params.blur.z = 1.0f;
        params.weight = weightVector(step.weight);
        params_.set(params);
        half.bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
        blurred.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
        sum.bindImage(SUBSCAN_IMAGE_OUT1, GL_READ_WRITE);
        stages_.runOverRegion(BlurAccumulate, region);
        glMemoryBarrier(kImageWritesBarrier);
    }

    sum.bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    resources.texture("albedo").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    resources.texture("specular").bindImage(SUBSCAN_IMAGE_IN3, GL_READ_ONLY);
    if (frame.restricted()) {
        frame.clear(radiance);
    }
    radiance.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    stages_.runOverRegion(Combine, region);
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
