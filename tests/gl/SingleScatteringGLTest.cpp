// The single-scattering pass on inputs uploaded by the test (a reconstructed surface as the
// shading pass leaves it): against the closed form of a flat semi-infinite slab (DESIGN.md
// §6.3), against the CPU estimator of the same formula, and against the limits the physics
// sets — no scattering without albedo, a slab value independent of the extinction, no pixel
// brighter than the single-scattering bound, nothing from a nearer object cast on a farther
// one. Coefficients from colour against the CPU inversion of R_d, from a material exactly.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "render/Renderer.h"
#include "render/SingleScatteringPass.h"
#include "scan/SyntheticScenes.h"
#include "sss/Dipole.h"
#include "sss/MaterialLibrary.h"
#include "sss/SingleScattering.h"
#include "support/GlTestSupport.h"
#include "support/PassHarness.h"

namespace subscan {
namespace {

using test::PassHarness;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kPi = std::numbers::pi;

/// A plane (view space: unit normal, a point on it) or two, as the reconstruction would leave
/// them: depth, normals, albedo.
struct SurfaceInputs {
    int width = 0, height = 0;
    std::vector<float> depth;
    std::vector<glm::dvec3> normal;
    std::vector<Rgb> albedo;

    SurfaceInputs(int w, int h)
        : width(w), height(h), depth(w * h, kInf), normal(w * h), albedo(w * h) {}
    int index(int x, int y) const { return y * width + x; }
};

/// Depth along each pixel centre's ray to the plane through `point` with `normal`.
void addPlane(SurfaceInputs& inputs, const PassHarness& harness, const glm::dvec3& normal,
              const glm::dvec3& point, const Rgb& albedo, int firstColumn = 0,
              int lastColumn = -1) {
    lastColumn = lastColumn < 0 ? inputs.width - 1 : lastColumn;
    for (int y = 0; y < inputs.height; ++y) {
        for (int x = firstColumn; x <= lastColumn; ++x) {
            const glm::dvec3 ray = harness.viewPosition(x + 0.5, y + 0.5, 1.0);
            const double depth = glm::dot(normal, point) / glm::dot(normal, ray);
            const int i = inputs.index(x, y);
            inputs.depth[i] = static_cast<float>(depth);
            inputs.normal[i] = normal;
            inputs.albedo[i] = albedo;
        }
    }
}

struct PassOutputs {
    std::vector<Rgb> single, sigmaSPrime, sigmaA, radiance;
};

std::vector<Rgb> rgbOf(const std::vector<float>& rgba) {
    std::vector<Rgb> out(rgba.size() / 4);
    for (std::size_t i = 0; i < out.size(); ++i) {
        out[i] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]};
    }
    return out;
}

/// Uploads the inputs (radiance: a constant 0.25 on the surface, to see that it is kept) and
/// runs the pass; the normals and albedo are replaced by what the GPU holds (half floats).
PassOutputs runPass(PassHarness& harness, SurfaceInputs& inputs,
                    SingleScatteringBase base = SingleScatteringBase::Radiance) {
    FrameResources& resources = harness.resources();
    const int w = inputs.width, h = inputs.height;
    resources.ensureTexture("surfaceDepth", TextureFormat::R32F, w, h).uploadFloats(inputs.depth);
    std::vector<float> normals, albedo, radiance;
    for (int i = 0; i < w * h; ++i) {
        const glm::dvec3& n = inputs.normal[i];
        normals.insert(normals.end(), {float(n.x), float(n.y), float(n.z), 0.0f});
        const Rgb& a = inputs.albedo[i];
        albedo.insert(albedo.end(), {float(a[0]), float(a[1]), float(a[2]), 1.0f});
        const float value = std::isinf(inputs.depth[i]) ? 0.0f : 0.25f;
        radiance.insert(radiance.end(), {value, value, value, 1.0f});
    }
    Texture& normalTexture = resources.ensureTexture("normals", TextureFormat::RGBA16F, w, h);
    normalTexture.uploadFloats(normals);
    Texture& albedoTexture = resources.ensureTexture("albedo", TextureFormat::RGBA16F, w, h);
    albedoTexture.uploadFloats(albedo);
    const std::string baseName =
        base == SingleScatteringBase::Radiance ? "radiance" : "scatteredRadiance";
    resources.ensureTexture(baseName, TextureFormat::RGBA16F, w, h).uploadFloats(radiance);
    const std::vector<Rgb> gpuNormals = rgbOf(normalTexture.readFloats());
    inputs.albedo = rgbOf(albedoTexture.readFloats());
    for (int i = 0; i < w * h; ++i) {
        inputs.normal[i] = {gpuNormals[i][0], gpuNormals[i][1], gpuNormals[i][2]};
    }
    SingleScatteringPass pass(harness.sources(), base);
    FrameContext frame = harness.context();
    pass.execute(frame);
    return {rgbOf(resources.texture("singleScattering").readFloats()),
            rgbOf(resources.texture("sigmaSPrime").readFloats()),
            rgbOf(resources.texture("sigmaA").readFloats()),
            rgbOf(resources.texture("scatteredRadiance").readFloats())};
}

/// Scene units are millimetres (the coefficients' unit), the head light off unless asked.
RenderSettings singleSettings(CoefficientSource source, const std::string& material, float g,
                              int samples) {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Sss;
    ScatteringSettings& scattering = settings.scattering;
    scattering.method = ScatteringMethod::Single;
    scattering.coefficients = source;
    scattering.material = material;
    scattering.unit = SceneUnit::Millimetre;
    scattering.phaseG = g;
    scattering.singleSamples = samples;
    settings.shading.headLight = glm::vec3(0.0f);
    return settings;
}

glm::dvec3 normalised(double x, double y, double z) {
    return glm::normalize(glm::dvec3(x, y, z));
}

/// A plane facing the camera tilted by θo about the x axis and a light θi from its normal: at
/// the image centre the eye sees the plane at θo, other pixels at their own angles.
struct SlabCase {
    double lightDegrees, viewDegrees;
};

glm::dvec3 tiltedNormal(double degrees) {
    const double t = degrees * kPi / 180.0;
    return {0.0, std::sin(t), std::cos(t)};
}

/// A direction θ from `normal` in the plane containing it and the x axis.
glm::dvec3 lightFromNormal(const glm::dvec3& normal, double degrees) {
    const double t = degrees * kPi / 180.0;
    return glm::normalize(std::cos(t) * normal + std::sin(t) * glm::dvec3(-1.0, 0.0, 0.0));
}

ScatteringMedium mediumOf(const Material& material, int channel, double g) {
    return {(*material.sigmaSPrime)[channel] / (1.0 - g), (*material.sigmaA)[channel], material.eta,
            g};
}

TEST(SingleScatteringGLTest, FlatSlabMatchesTheClosedForm) {
    constexpr int kWidth = 40, kHeight = 30;
    const glm::vec3 lightColor{0.9f, 0.7f, 1.1f};
    int compared = 0;
    for (const std::string material : {"marble", "skin1"}) {
        for (const float g : {0.0f, 0.5f}) {
            for (const SlabCase slab : {SlabCase{0, 0}, {35, 20}, {60, 45}, {75, 10}, {20, 65}}) {
                // 63 samples: the quadrature's error is under 0.1 % there (SingleScatteringTest).
                RenderSettings settings =
                    singleSettings(CoefficientSource::Material, material, g, 63);
                const glm::dvec3 normal = tiltedNormal(slab.viewDegrees);
                const glm::dvec3 toLight = lightFromNormal(normal, slab.lightDegrees);
                settings.shading.lights = {{glm::vec3(toLight), lightColor}};
                // 40 mm away with f = 32 px: a pixel is 1.2 mm, about 3 mean free paths of
                // marble, so the march crosses pixels and the tangent planes matter.
                PassHarness harness(kWidth, kHeight, settings, 1.0);
                SurfaceInputs inputs(kWidth, kHeight);
                addPlane(inputs, harness, normal, {0.0, 0.0, -40.0}, {0.5, 0.5, 0.5});
                const PassOutputs out = runPass(harness, inputs);
                const Material& measured = findMaterial(material);
                for (int y = 0; y < kHeight; ++y) {
                    for (int x = 0; x < kWidth; ++x) {
                        const int i = inputs.index(x, y);
                        const glm::dvec3 toEye = glm::normalize(
                            -harness.viewPosition(x + 0.5, y + 0.5, inputs.depth[i]));
                        for (int c = 0; c < 3; ++c) {
                            const double expected = semiInfiniteSlabRadiance(
                                mediumOf(measured, c, g), glm::normalize(inputs.normal[i]), toLight,
                                toEye, kPi * lightColor[c]);
                            // 1.5 %: the 63-sample quadrature (< 0.1 %), the half-float normal
                            // (its cosines move by ~1e-3, more near grazing) and the half-float
                            // output (0.05 %). A wrong term (Fresnel, compression, 1/η², phase
                            // or a path length) moves the value by far more at these angles.
                            EXPECT_NEAR(out.single[i][c], expected, 0.015 * expected + 1e-6)
                                << material << " g " << g << " θi " << slab.lightDegrees
                                << " θo(centre) " << slab.viewDegrees << " pixel " << x << "," << y
                                << " channel " << c;
                            ++compared;
                        }
                        EXPECT_NEAR(out.radiance[i][0], 0.25 + out.single[i][0],
                                    2e-3 * (0.25 + out.single[i][0]))
                            << "the base radiance is kept and single scattering added";
                    }
                }
            }
        }
    }
    EXPECT_EQ(compared, 2 * 2 * 5 * kWidth * kHeight * 3);
}

TEST(SingleScatteringGLTest, HeadLightOnTheSlabMatchesTheClosedForm) {
    // The head light enters along each sample's own line of sight (no march): its value is the
    // slab's with the light at the eye, ω_i = ω_o per pixel.
    constexpr int kWidth = 40, kHeight = 30;
    RenderSettings settings = singleSettings(CoefficientSource::Material, "skin2", 0.3f, 63);
    settings.shading.headLight = glm::vec3(0.8f);
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    const glm::dvec3 normal = tiltedNormal(40.0);
    addPlane(inputs, harness, normal, {0.0, 0.0, -40.0}, {0.5, 0.5, 0.5});
    const PassOutputs out = runPass(harness, inputs);
    for (int i = 0; i < kWidth * kHeight; ++i) {
        const glm::dvec3 toEye = glm::normalize(
            -harness.viewPosition(i % kWidth + 0.5, i / kWidth + 0.5, inputs.depth[i]));
        for (int c = 0; c < 3; ++c) {
            const double expected =
                semiInfiniteSlabRadiance(mediumOf(findMaterial("skin2"), c, 0.3),
                                         glm::normalize(inputs.normal[i]), toEye, toEye, kPi * 0.8);
            // As in the directional case: quadrature, half-float normal and output.
            EXPECT_NEAR(out.single[i][c], expected, 0.015 * expected) << i << " channel " << c;
        }
    }
}

TEST(SingleScatteringGLTest, EightSamplesMatchTheCpuEstimator) {
    // The default sample count against the CPU estimator with the GPU's strata: the same
    // quadrature, so only float precision separates them.
    constexpr int kWidth = 32, kHeight = 24;
    RenderSettings settings = singleSettings(CoefficientSource::Material, "ketchup", 0.4f, 8);
    const glm::dvec3 normal = tiltedNormal(25.0);
    const glm::dvec3 toLight = lightFromNormal(normal, 50.0);
    settings.shading.lights = {{glm::vec3(toLight), glm::vec3(1.0f)}};
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    addPlane(inputs, harness, normal, {0.0, 0.0, -30.0}, {0.5, 0.5, 0.5});
    const PassOutputs out = runPass(harness, inputs);
    const Material& ketchup = findMaterial("ketchup");
    Rgb sigmaS{}, sigmaT{};
    for (int c = 0; c < 3; ++c) {
        sigmaS[c] = mediumOf(ketchup, c, 0.4).sigmaS;
        sigmaT[c] = mediumOf(ketchup, c, 0.4).sigmaT();
    }
    for (int i = 0; i < kWidth * kHeight; ++i) {
        const glm::dvec3 n = glm::normalize(inputs.normal[i]);
        const glm::dvec3 toEye = glm::normalize(
            -harness.viewPosition(i % kWidth + 0.5, i / kWidth + 0.5, inputs.depth[i]));
        const double cosEyeInside = refractedCosine(glm::dot(n, toEye), ketchup.eta);
        const double cosLightInside = refractedCosine(glm::dot(n, toLight), ketchup.eta);
        const Rgb expected =
            estimateSingleScattering(sigmaS, sigmaT, 8, {0.5, 0.5, 0.5}, [&](double s) {
                return LightAtSample{
                    kPi * singleScatteringGeometry(toLight, n, toEye, n, ketchup.eta, 0.4),
                    s * cosEyeInside / cosLightInside};
            });
        for (int c = 0; c < 3; ++c) {
            // 0.5 %: float arithmetic on the GPU and the half-float output; the quadrature is the
            // same. (Against the closed form the 8-sample midpoint rule is off by up to 5 %.)
            EXPECT_NEAR(out.single[i][c], expected[c], 5e-3 * expected[c] + 1e-7)
                << i << " channel " << c;
        }
    }
}

TEST(SingleScatteringGLTest, SlabValueDoesNotDependOnTheExtinction) {
    // Coefficients from colour: scaling ld scales σt and σs alike, and the semi-infinite slab's
    // single scattering depends only on their ratio.
    constexpr int kWidth = 24, kHeight = 18;
    std::vector<Rgb> results[2];
    for (int run = 0; run < 2; ++run) {
        RenderSettings settings = singleSettings(CoefficientSource::Color, "marble", 0.0f, 8);
        settings.scattering.meanFreePathMm = kMarbleMeanFreePathMm * (run == 0 ? 1.0f : 4.0f);
        const glm::dvec3 normal = tiltedNormal(30.0);
        settings.shading.lights = {{glm::vec3(lightFromNormal(normal, 45.0)), glm::vec3(1.0f)}};
        // No head light: a light at the eye reaches deeper samples from other directions, so
        // its slab value does depend on how deep the samples lie.
        PassHarness harness(kWidth, kHeight, settings, 1.0);
        SurfaceInputs inputs(kWidth, kHeight);
        addPlane(inputs, harness, normal, {0.0, 0.0, -30.0}, {0.8, 0.6, 0.3});
        results[run] = runPass(harness, inputs).single;
    }
    for (std::size_t i = 0; i < results[0].size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            // 0.3 %: the two quadratures are the same in units of the free path; float
            // arithmetic and the half-float outputs differ.
            EXPECT_NEAR(results[1][i][c], results[0][i][c], 3e-3 * results[0][i][c]) << i;
            EXPECT_GT(results[0][i][c], 0.0);
        }
    }
}

TEST(SingleScatteringGLTest, NoAlbedoScattersNothing) {
    constexpr int kWidth = 16, kHeight = 12;
    RenderSettings settings = singleSettings(CoefficientSource::Color, "marble", 0.2f, 8);
    settings.shading.headLight = glm::vec3(1.0f);
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    addPlane(inputs, harness, tiltedNormal(10.0), {0.0, 0.0, -20.0}, {0.0, 0.0, 0.0});
    // One column of a faint red: only its red channel may scatter.
    for (int y = 0; y < kHeight; ++y) {
        inputs.albedo[inputs.index(5, y)] = {0.01, 0.0, 0.0};
    }
    const PassOutputs out = runPass(harness, inputs);
    for (int i = 0; i < kWidth * kHeight; ++i) {
        const bool red = i % kWidth == 5;
        for (int c = 0; c < 3; ++c) {
            // α′ = 0 gives σs′ = 0 exactly (the table's first entry is u = 1).
            if (red && c == 0) {
                EXPECT_GT(out.single[i][c], 0.0) << i;
            } else {
                EXPECT_EQ(out.single[i][c], 0.0) << i << " channel " << c;
                EXPECT_EQ(out.sigmaSPrime[i][c], 0.0) << i << " channel " << c;
                EXPECT_GT(out.sigmaA[i][c], 0.0) << i << " channel " << c;
            }
        }
    }
}

TEST(SingleScatteringGLTest, CoefficientsFromColourMatchTheCpuInversion) {
    constexpr int kWidth = 12, kHeight = 8;
    for (const float eta : {1.3f, 1.5f}) {
        RenderSettings settings = singleSettings(CoefficientSource::Color, "marble", 0.0f, 3);
        settings.scattering.eta = eta;
        settings.scattering.meanFreePathMm = {2.0f, 5.0f, 0.7f};
        PassHarness harness(kWidth, kHeight, settings, 1.0);
        SurfaceInputs inputs(kWidth, kHeight);
        addPlane(inputs, harness, tiltedNormal(0.0), {0.0, 0.0, -20.0}, {0.05, 0.45, 0.93});
        // A few pixels of other colours, up to one past the table's clamp.
        inputs.albedo[3] = {0.999, 1.0, 0.0005};
        inputs.albedo[20] = {0.2, 0.7, 0.998};
        const PassOutputs out = runPass(harness, inputs);
        const ReducedAlbedoTable table(eta);
        for (int i = 0; i < kWidth * kHeight; ++i) {
            const ScatteringCoefficients cpu =
                coefficientsFromReflectance(table, inputs.albedo[i], {2.0, 5.0, 0.7});
            for (int c = 0; c < 3; ++c) {
                // The acceptance bound, 1 %. Interpolating u = √(1 − α′) over 4096 entries
                // in R_d errs by < 1e-5 relative (DipoleTest), the rest is float arithmetic.
                EXPECT_NEAR(out.sigmaSPrime[i][c], cpu.sigmaSPrime[c], 0.01 * cpu.sigmaSPrime[c])
                    << "η " << eta << " pixel " << i << " channel " << c;
                EXPECT_NEAR(out.sigmaA[i][c], cpu.sigmaA[c], 0.01 * cpu.sigmaA[c])
                    << "η " << eta << " pixel " << i << " channel " << c;
            }
        }
    }
}

TEST(SingleScatteringGLTest, MaterialCoefficientsAreExactAndOnlyOnTheSurface) {
    constexpr int kWidth = 12, kHeight = 8;
    const RenderSettings settings = singleSettings(CoefficientSource::Material, "apple", 0.0f, 3);
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    addPlane(inputs, harness, tiltedNormal(0.0), {0.0, 0.0, -20.0}, {0.3, 0.3, 0.3}, 0, 7);
    const PassOutputs out = runPass(harness, inputs);
    const Material& apple = findMaterial("apple");
    for (int i = 0; i < kWidth * kHeight; ++i) {
        const bool surface = !std::isinf(inputs.depth[i]);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(out.sigmaSPrime[i][c],
                      surface ? static_cast<float>((*apple.sigmaSPrime)[c]) : 0.0f)
                << i;
            EXPECT_EQ(out.sigmaA[i][c], surface ? static_cast<float>((*apple.sigmaA)[c]) : 0.0f)
                << i;
            if (!surface) {
                EXPECT_EQ(out.single[i][c], 0.0) << i;
                EXPECT_EQ(out.radiance[i][c], 0.0) << i;
            }
        }
    }
}

TEST(SingleScatteringGLTest, NearerObjectCastsNothingOnAFartherOne) {
    // Left: a plane 20 mm away; right: another 70 mm away, lit from the left, so the marches of
    // the far plane's pixels beside the silhouette run behind the near plane. The far plane
    // must look as if it were alone: the slab's closed form up to its own pixels.
    constexpr int kWidth = 48, kHeight = 16;
    const glm::dvec3 normal{0.0, 0.0, 1.0};
    const glm::dvec3 toLight = normalised(-1.0, 0.0, 0.6);
    RenderSettings settings = singleSettings(CoefficientSource::Material, "skin1", 0.0f, 63);
    settings.shading.lights = {{glm::vec3(toLight), glm::vec3(1.0f)}};
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    const int edge = kWidth / 2;
    addPlane(inputs, harness, normal, {0.0, 0.0, -20.0}, {0.5, 0.5, 0.5}, 0, edge - 1);
    addPlane(inputs, harness, normal, {0.0, 0.0, -70.0}, {0.5, 0.5, 0.5}, edge);
    const PassOutputs out = runPass(harness, inputs);
    const Material& skin = findMaterial("skin1");
    for (int y = 0; y < kHeight; ++y) {
        for (int x = edge; x < kWidth; ++x) {
            const int i = inputs.index(x, y);
            const glm::dvec3 toEye =
                glm::normalize(-harness.viewPosition(x + 0.5, y + 0.5, inputs.depth[i]));
            for (int c = 0; c < 3; ++c) {
                const double expected = semiInfiniteSlabRadiance(
                    mediumOf(skin, c, 0.0), glm::normalize(inputs.normal[i]), toLight, toEye, kPi);
                // As for the slab alone (1.5 %); a march stopped by the near plane would find
                // the light entering at the silhouette, far brighter.
                EXPECT_NEAR(out.single[i][c], expected, 0.015 * expected)
                    << "far pixel " << x << "," << y << " channel " << c;
            }
        }
    }
}

TEST(SingleScatteringGLTest, AddsToTheBlurredRadianceInPlace) {
    constexpr int kWidth = 16, kHeight = 12;
    RenderSettings settings = singleSettings(CoefficientSource::Color, "marble", 0.0f, 4);
    settings.scattering.method = ScatteringMethod::Both;
    settings.shading.headLight = glm::vec3(1.0f);
    PassHarness harness(kWidth, kHeight, settings, 1.0);
    SurfaceInputs inputs(kWidth, kHeight);
    addPlane(inputs, harness, tiltedNormal(20.0), {0.0, 0.0, -20.0}, {0.7, 0.7, 0.7}, 0, 9);
    const PassOutputs out = runPass(harness, inputs, SingleScatteringBase::Scattered);
    for (int i = 0; i < kWidth * kHeight; ++i) {
        const bool surface = !std::isinf(inputs.depth[i]);
        for (int c = 0; c < 3; ++c) {
            const double expected = surface ? 0.25 + out.single[i][c] : 0.0;
            // Half-float sum: 2^-11 relative.
            EXPECT_NEAR(out.radiance[i][c], expected, 1e-3 * expected) << i;
            EXPECT_EQ(out.single[i][c] > 0.0, surface) << i;
        }
    }
}

TEST(SingleScatteringGLTest, AGaussianOnlyMaterialHasNoCoefficients) {
    const RenderSettings settings =
        singleSettings(CoefficientSource::Material, "marble-jimenez", 0.0f, 8);
    try {
        SingleScatteringPass::parameters(settings.scattering);
        FAIL() << "accepted a material without σs′ and σa";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), testing::HasSubstr("'marble-jimenez'"));
        EXPECT_THAT(error.what(), testing::HasSubstr("coefficients 'color'"));
    }
}

/// The pixels of a rendered synthetic scene and what the renderer left for them.
struct RenderedFrame {
    std::vector<float> depth;
    std::vector<Rgb> normals, single, sigmaSPrime, sigmaA;
    std::vector<std::uint8_t> image;
};

RenderedFrame renderScene(Renderer& renderer, const Camera& camera,
                          const RenderSettings& settings) {
    renderer.render(camera, settings, FrameOutputs::Everything);
    const FrameResources& resources = renderer.resources();
    RenderedFrame frame;
    frame.depth = resources.texture("surfaceDepth").readFloats();
    frame.normals = rgbOf(resources.texture("normals").readFloats());
    frame.image = renderer.readImage();
    if (resources.has("singleScattering")) {
        frame.single = rgbOf(resources.texture("singleScattering").readFloats());
        frame.sigmaSPrime = rgbOf(resources.texture("sigmaSPrime").readFloats());
        frame.sigmaA = rgbOf(resources.texture("sigmaA").readFloats());
    }
    return frame;
}

TEST(SingleScatteringGLTest, NoPixelIsBrighterThanTheBoundAndTheBackgroundIsUntouched) {
    const PointCloud cloud = makeSyntheticScene("sculpture?points=60000");
    const Camera camera = orbitCamera(cloud.bounds, OrbitView{}, 96, 80, 45.0);
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    const RenderedFrame surface = renderScene(renderer, camera, settings);

    settings.raster.mode = RenderMode::Sss;
    settings.scattering.unit = SceneUnit::Centimetre;      // a sculpture of a few cm
    settings.scattering.meanFreePathMm = glm::vec3(3.0f);  // grey: α the same in every channel
    settings.shading.lights = {{{-1.0f, 1.0f, 0.5f}, glm::vec3(0.8f)},
                               {{1.0f, -0.2f, -1.0f}, glm::vec3(1.2f)}};
    const glm::vec3 headLight = settings.shading.headLight;
    for (const ScatteringMethod method : {ScatteringMethod::Single, ScatteringMethod::Both}) {
        settings.scattering.method = method;
        const RenderedFrame scattered = renderScene(renderer, camera, settings);
        const double eta = scatteringEta(settings.scattering);
        int lit = 0;
        for (std::size_t pixel = 0; pixel < scattered.depth.size(); ++pixel) {
            if (std::isinf(scattered.depth[pixel])) {
                ASSERT_TRUE(std::isinf(surface.depth[pixel]));
                for (int c = 0; c < 4; ++c) {
                    EXPECT_EQ(scattered.image[4 * pixel + c], surface.image[4 * pixel + c])
                        << "background pixel " << pixel;
                }
                continue;
            }
            // The integrand without e^(−σt s_i′), T_i and cos θi/cos θi′ (each at most 1)
            // integrates to α p T_o E/η² per light; with g = 0, p = 1/(4π) and E = πc. The
            // quadrature of a grey medium sums exactly to α over its samples.
            const glm::dvec3 n =
                glm::normalize(glm::dvec3(scattered.normals[pixel][0], scattered.normals[pixel][1],
                                          scattered.normals[pixel][2]));
            const int x = static_cast<int>(pixel) % camera.width;
            const int y = static_cast<int>(pixel) / camera.width;
            const double f = camera.focalLengthPixels();
            const glm::dvec3 toEye = glm::normalize(-glm::dvec3(
                (x + 0.5 - 0.5 * camera.width) / f, (0.5 * camera.height - y - 0.5) / f, -1.0));
            const double exitTerm = fresnelTransmittance(glm::dot(n, toEye), eta) / (eta * eta);
            for (int c = 0; c < 3; ++c) {
                const double sigmaS = scattered.sigmaSPrime[pixel][c];
                const double albedo = sigmaS / (sigmaS + scattered.sigmaA[pixel][c]);
                double lights = headLight[c];
                for (const DirectionalLight& light : settings.shading.lights) {
                    lights += light.radiance[c];
                }
                const double bound = albedo * exitTerm * lights / 4.0;
                // 0.5 %: the half-float normal's cosine in T_o and float rounding.
                EXPECT_LE(scattered.single[pixel][c], bound * 1.005 + 1e-6)
                    << "pixel " << pixel << " channel " << c;
            }
            lit += scattered.single[pixel][0] > 0.0 ? 1 : 0;
        }
        EXPECT_GT(lit, 500) << toString(method);  // the sculpture covers ~1/4 of 96x80
    }
}

}  // namespace
}  // namespace subscan

namespace subscan {
namespace {

TEST(SingleScatteringGLTest, PictureFramesSkipOnlyTheExports) {
    // Frames for the picture alone leave the term and the coefficients unwritten; the picture
    // itself must be byte for byte the exporting frame's.
    const PointCloud cloud = makeSyntheticScene("sculpture?points=30000");
    const Camera camera = orbitCamera(cloud.bounds, OrbitView{}, 64, 56, 45.0);
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Sss;
    settings.scattering.method = ScatteringMethod::Single;
    settings.scattering.unit = SceneUnit::Centimetre;
    settings.shading.lights = {{{-1.0f, 1.0f, 0.5f}, glm::vec3(0.8f)}};
    renderer.render(camera, settings, FrameOutputs::Everything);
    const std::vector<std::uint8_t> exported = renderer.readImage();
    // A frame of another light for the picture alone: its term would differ, but stays unwritten.
    settings.shading.lights[0].radiance = glm::vec3(2.0f);
    const std::vector<float> term = renderer.resources().texture("singleScattering").readFloats();
    renderer.render(camera, settings, FrameOutputs::Picture);
    EXPECT_EQ(renderer.resources().texture("singleScattering").readFloats(), term);
    EXPECT_NE(renderer.readImage(), exported);
    settings.shading.lights[0].radiance = glm::vec3(0.8f);
    renderer.render(camera, settings, FrameOutputs::Picture);
    EXPECT_EQ(renderer.readImage(), exported);
}

}  // namespace
}  // namespace subscan
