// The directional lights' maps (render/LightMaps.h). Shadows: the shadow a floating plate casts
// on a larger one against its analytic projection; lit flat plates without shadow acne. Single
// scattering through the maps: a slab lit from behind against its closed form. A light map's
// depth against the plane it sees; maps rebuilt when, and only when, their light or the
// settings that shape them change.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Camera.h"
#include "render/LightMaps.h"
#include "render/Renderer.h"
#include "sss/GaussianSet.h"
#include "sss/MaterialLibrary.h"
#include "sss/SingleScattering.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

constexpr double kSpacing = 0.005;  // the plates' grid, scene units

enum class Facing { Y, Z };

/// A square plate of white points in the plane y = `height` (Facing::Y; centred on (x, z) =
/// `centre`) or z = `height` (Facing::Z; centred on (x, y) = `centre`): one point in the middle
/// of each `spacing`-wide cell of the square, so that the points' cells tile exactly the plate
/// they stand for; `noise` moves each point off the plane by a uniform amount within ±noise.
void addPlate(PointCloudBuilder& builder, double height, double side, glm::dvec2 centre,
              double noise = 0.0, Facing facing = Facing::Y, double spacing = kSpacing) {
    std::mt19937 random(1);
    std::uniform_real_distribution<double> jitter(-noise, noise);
    const int count = static_cast<int>(std::lround(side / spacing));
    for (int i = 0; i < count; ++i) {
        for (int k = 0; k < count; ++k) {
            const double u = centre.x - 0.5 * side + (i + 0.5) * spacing;
            const double v = centre.y - 0.5 * side + (k + 0.5) * spacing;
            const double w = height + (noise > 0.0 ? jitter(random) : 0.0);
            PointRecord point;
            point.position = facing == Facing::Y ? glm::dvec3(u, w, v) : glm::dvec3(u, v, w);
            point.color = {255, 255, 255, 255};
            builder.add(point);
        }
    }
}

PointCloud finish(PointCloudBuilder& builder) {
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

/// The surface mode under one white directional light and nothing else, so that a white
/// surface's radiance is the cosine of the light's angle where lit and 0 in shadow.
RenderSettings lightOnly(const glm::dvec3& towardsLight) {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.shading.headLight = glm::vec3(0.0f);
    settings.shading.ambient = glm::vec3(0.0f);
    settings.shading.specular = 0.0f;
    settings.shading.lights = {{glm::vec3(glm::normalize(towardsLight)), glm::vec3(1.0f)}};
    return settings;
}

/// A 512² pinhole camera at `eye` looking at `target`.
Camera lookingAt(const glm::dvec3& eye, const glm::dvec3& target, const glm::dvec3& up) {
    Camera camera;
    camera.width = 512;
    camera.height = 512;
    camera.fovyDegrees = 45.0;
    camera.nearPlane = 0.5;
    camera.farPlane = 10.0;
    camera.view = glm::lookAt(eye, target, up);
    return camera;
}

/// The world-space ray through pixel (x, y)'s centre.
struct Ray {
    glm::dvec3 origin, direction;
};
Ray pixelRay(const Camera& camera, int x, int y) {
    const glm::dvec3 inView = pixelCentreDirection(camera, x, y);
    const glm::dmat4 worldFromView = glm::inverse(camera.view);
    return {glm::dvec3(worldFromView * glm::dvec4(0, 0, 0, 1)),
            glm::normalize(glm::dvec3(worldFromView * glm::dvec4(inView, 0.0)))};
}

/// Where `ray` meets the plane where coordinate `axis` (1: y) is `height`, if it does in front
/// of its origin.
std::optional<glm::dvec3> hitPlane(const Ray& ray, double height, int axis = 1) {
    const double t = (height - ray.origin[axis]) / ray.direction[axis];
    if (!(t > 0.0)) {
        return std::nullopt;
    }
    return ray.origin + t * ray.direction;
}

bool insideSquare(const glm::dvec3& p, glm::dvec2 centre, double side, double inset = 0.0) {
    return std::abs(p.x - centre.x) <= 0.5 * side - inset &&
           std::abs(p.z - centre.y) <= 0.5 * side - inset;
}

struct Shaded {
    std::vector<float> radiance;  // RGBA
    std::vector<float> depth;
};

Shaded renderShaded(Renderer& renderer, const Camera& camera, const RenderSettings& settings) {
    renderer.render(camera, settings, FrameOutputs::Everything);
    return {renderer.resources().texture("radiance").readFloats(),
            renderer.resources().texture("surfaceDepth").readFloats()};
}

TEST(LightMapsGLTest, FloatingPlateCastsItsAnalyticShadow) {
    // A 2 x 2 plate at y = 0 and a 0.6 x 0.6 plate 0.6 above it, seen from straight above;
    // the light comes from 45 degrees, so the shadow is the upper plate moved by -0.6 in x.
    const double upperHeight = 0.6;
    const double upperSide = 0.6;
    const glm::dvec2 upperCentre(0.35, 0.0);
    PointCloudBuilder builder({.color = true}, 170000);
    addPlate(builder, 0.0, 2.0, {0.0, 0.0});
    addPlate(builder, upperHeight, upperSide, upperCentre);
    Renderer renderer(test::glTestContext(), finish(builder), kSpacing);

    const glm::dvec3 towardsLight = glm::normalize(glm::dvec3(1.0, 1.0, 0.0));
    const RenderSettings settings = lightOnly(towardsLight);
    const Camera camera = lookingAt({0.0, 3.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, -1.0});
    const Shaded shaded = renderShaded(renderer, camera, settings);

    const double lit = towardsLight.y;  // the lower plate's cosine
    std::size_t both = 0, either = 0, truth = 0, uncovered = 0;
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const Ray ray = pixelRay(camera, x, y);
            const std::optional<glm::dvec3> upper = hitPlane(ray, upperHeight);
            if (upper && insideSquare(*upper, upperCentre, upperSide)) {
                continue;  // the upper plate itself
            }
            const std::optional<glm::dvec3> lower = hitPlane(ray, 0.0);
            // A margin of 2 h from the lower plate's edge, where the surface ends.
            if (!lower || !insideSquare(*lower, {0.0, 0.0}, 2.0, 2.0 * kSpacing)) {
                continue;
            }
            const glm::dvec3 towardsOccluder =
                *lower + (upperHeight / towardsLight.y) * towardsLight;
            const bool shadowed = insideSquare(towardsOccluder, upperCentre, upperSide);
            const std::size_t i = static_cast<std::size_t>(y) * camera.width + x;
            uncovered += std::isinf(shaded.depth[i]) ? 1 : 0;
            // Half the lit value: the middle of a soft edge.
            const bool renderedShadow = shaded.radiance[4 * i] < 0.5 * lit;
            truth += shadowed ? 1 : 0;
            both += shadowed && renderedShadow ? 1 : 0;
            either += shadowed || renderedShadow ? 1 : 0;
        }
    }
    EXPECT_EQ(uncovered, 0u) << "the lower plate should be surface everywhere";
    ASSERT_GT(truth, 10000u) << "the shadow should cover a good part of the view";
    const double iou = static_cast<double>(both) / static_cast<double>(either);
    // The shadow is about 125 pixels wide at 512² (a pixel is about h here). Its outline lies
    // where the light map's reconstruction ends the upper plate: within a texel on three sides;
    // on the fourth, where the light's view sees the lower plate right beside the upper one,
    // hidden point removal takes about two texels of the lower plate near that depth jump for
    // hidden, and the fill gives them the occluder's depth. Measured: 0.959. One pixel of
    // shift along the whole outline costs about 0.03; 0.95 allows the measured edges and
    // fails a shadow that is one pixel larger all round or offset by half a texel.
    EXPECT_GE(iou, 0.95) << both << " of " << either << " pixels agree; " << truth
                         << " pixels are in the analytic shadow";
}

/// Pixels of the row through the floating plate's shadow, left of its middle, whose radiance
/// lies strictly between a tenth and nine tenths of the lit value: the width of the shadow's
/// left edge.
int softEdgePixels(float softness) {
    PointCloudBuilder builder({.color = true}, 170000);
    addPlate(builder, 0.0, 2.0, {0.0, 0.0});
    addPlate(builder, 0.6, 0.6, {0.35, 0.0});
    Renderer renderer(test::glTestContext(), finish(builder), kSpacing);
    const glm::dvec3 towardsLight = glm::normalize(glm::dvec3(1.0, 1.0, 0.0));
    RenderSettings settings = lightOnly(towardsLight);
    settings.shading.shadowSoftness = softness;
    const Camera camera = lookingAt({0.0, 3.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, -1.0});
    const Shaded shaded = renderShaded(renderer, camera, settings);
    const double lit = towardsLight.y;
    int partial = 0;
    const int y = camera.height / 2;
    for (int x = 0; x < camera.width; ++x) {
        // The shadow spans x -0.55..0.05 on the lower plate; its left edge is alone out there.
        if (hitPlane(pixelRay(camera, x, y), 0.0)->x > -0.25) {
            continue;
        }
        const float value = shaded.radiance[4 * (static_cast<std::size_t>(y) * camera.width + x)];
        partial += value > 0.1 * lit && value < 0.9 * lit ? 1 : 0;
    }
    return partial;
}

TEST(LightMapsGLTest, ShadowEdgesFadeOverTheSoftEdgesWidth) {
    // Taps (w − 1) texels apart, each a one-texel bilinear ramp: the edge climbs from a tenth
    // to nine tenths over w − 0.4 texels. A texel is h = 0.005 here, a pixel 0.00485 on the lower
    // plate, and the light at 45° stretches the map across that plate by √2.
    for (const float softness : {4.0f, 20.0f}) {
        const double expected = (softness - 0.4) * std::sqrt(2.0) * 0.005 / 0.00485;
        // Whole pixels at both ends of the ramp (1.5 pixels), and a tenth for the occluder's
        // outline in the map, which has a fringe of its own. Measured: 5 pixels for 5.2 at 4 h,
        // 29 for 28.6 at 20 h; taps half as far apart (the first version) gave 3 and 19.
        EXPECT_NEAR(softEdgePixels(softness), expected, 1.5 + 0.1 * expected)
            << "softness " << softness << " h";
    }
}

TEST(LightMapsGLTest, LitFlatPlatesShowNoAcne) {
    const Camera camera = lookingAt({0.0, 1.6, 1.6}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    for (const double noise : {0.0, 0.1 * kSpacing}) {
        PointCloudBuilder builder({.color = true}, 50000);
        addPlate(builder, 0.0, 1.0, {0.0, 0.0}, noise);
        Renderer renderer(test::glTestContext(), finish(builder), kSpacing);
        // From overhead to grazing, from the camera's side and across it.
        for (const glm::dvec3& towardsLight :
             {glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(0.5, 0.866, 0.0), glm::dvec3(0.0, 0.5, -0.866),
              glm::dvec3(-0.966, 0.259, 0.0)}) {
            RenderSettings settings = lightOnly(towardsLight);
            const Shaded shadowed = renderShaded(renderer, camera, settings);
            settings.shading.shadows = false;
            const Shaded unshadowed = renderShaded(renderer, camera, settings);
            std::size_t interior = 0, acne = 0;
            for (int y = 0; y < camera.height; ++y) {
                for (int x = 0; x < camera.width; ++x) {
                    const std::optional<glm::dvec3> p = hitPlane(pixelRay(camera, x, y), 0.0);
                    // 4 h in from the edge: the plate's own silhouette bends its normals.
                    if (!p || !insideSquare(*p, {0.0, 0.0}, 1.0, 4.0 * kSpacing)) {
                        continue;
                    }
                    const std::size_t i = static_cast<std::size_t>(y) * camera.width + x;
                    ++interior;
                    const float value = shadowed.radiance[4 * i];
                    // 1 %: the bar for "uniform"; half floats hold 0.1 %.
                    acne += value < 0.99f * unshadowed.radiance[4 * i] ? 1 : 0;
                }
            }
            ASSERT_GT(interior, 50000u);
            EXPECT_EQ(acne, 0u) << "noise " << noise << ", light (" << towardsLight.x << ", "
                                << towardsLight.y << ", " << towardsLight.z << ")";
        }
    }
}

/// A slab of marble between two plates of points (the faces z = 0 and z = -thickness, in
/// millimetres), seen from the front and lit from behind by one directional light: single
/// scattering alone, at the centre of the image.
struct BackLitSlab {
    double thickness;
    std::vector<Rgb> single;  // "singleScattering" per pixel
    Camera camera;
};

/// The faces of a slab, z = 0 (towards the camera) and z = −thickness, `side` wide.
PointCloud slab(double thickness, double side, double spacing) {
    PointCloudBuilder builder({.color = true},
                              2 * static_cast<std::size_t>(std::pow(side / spacing + 1.0, 2.0)));
    addPlate(builder, 0.0, side, {0.0, 0.0}, 0.0, Facing::Z, spacing);
    addPlate(builder, -thickness, side, {0.0, 0.0}, 0.0, Facing::Z, spacing);
    return finish(builder);
}

constexpr double kSlabSpacing = 0.01;  // mm: a twentieth of the thinnest slab
constexpr int kSlabSamples = 63;       // the most the pass takes but one (a multiple of 3)

/// Single scattering alone in marble (millimetres, the material's coefficients, kSlabSamples)
/// under one white directional light, its entries found by `path`.
RenderSettings marbleSingleScattering(const glm::dvec3& towardsLight, LightPath path,
                                      float g = 0.0f) {
    RenderSettings settings = lightOnly(towardsLight);
    settings.raster.mode = RenderMode::Sss;
    ScatteringSettings& scattering = settings.scattering;
    scattering.method = ScatteringMethod::Single;
    scattering.coefficients = CoefficientSource::Material;
    scattering.material = "marble";
    scattering.unit = SceneUnit::Millimetre;
    scattering.phaseG = g;
    scattering.singleSamples = kSlabSamples;
    scattering.lightPath = path;
    return settings;
}

BackLitSlab renderBackLitSlab(double thickness, const glm::dvec3& towardsLight, LightPath path) {
    // 2 mm wide: the light reaches the middle through the back face, not the sides, for the
    // thickest slab (0.76 mm) at the test's angle.
    Renderer renderer(test::glTestContext(), slab(thickness, 2.0, kSlabSpacing), kSlabSpacing);
    const RenderSettings settings = marbleSingleScattering(towardsLight, path);
    // 32² pixels over 0.4 mm: a pixel (0.0125 mm) holds at least one point of the front face,
    // so the back face never shows.
    Camera camera;
    camera.width = camera.height = 32;
    camera.fovyDegrees = 4.0;
    const double distance = 0.2 / std::tan(glm::radians(2.0));
    camera.view =
        glm::lookAt(glm::dvec3(0.0, 0.0, distance), glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
    camera.nearPlane = distance - 1.0;
    camera.farPlane = distance + 2.0;
    renderer.render(camera, settings, FrameOutputs::Everything);
    std::vector<Rgb> single;
    const std::vector<float> rgba = renderer.resources().texture("singleScattering").readFloats();
    for (std::size_t i = 0; i < rgba.size(); i += 4) {
        single.push_back({rgba[i], rgba[i + 1], rgba[i + 2]});
    }
    return {thickness, single, camera};
}

TEST(LightMapsGLTest, SlabLitFromBehindMatchesTheClosedFormThroughTheLightMap) {
    const Material& marble = measuredMaterial("marble");
    const double meanFreePath = 1.0 / ((*marble.sigmaSPrime)[1] + (*marble.sigmaA)[1]);  // green
    const glm::dvec3 front(0.0, 0.0, 1.0);
    const glm::dvec3 towardsLight = glm::normalize(glm::dvec3(0.4, 0.2, -1.0));
    const double irradiance = std::numbers::pi;  // a light of value 1
    for (const double paths : {0.5, 1.0, 2.0}) {
        const BackLitSlab slab =
            renderBackLitSlab(paths * meanFreePath, towardsLight, LightPath::LightMap);
        const glm::dvec3 eye = slab.camera.eye();
        int checked = 0;
        // The middle 16² pixels: far from the plates' edges.
        for (int y = 8; y < 24; ++y) {
            for (int x = 8; x < 24; ++x) {
                const glm::dvec3 at = *hitPlane(pixelRay(slab.camera, x, y), 0.0, 2);
                const glm::dvec3 toEye = glm::normalize(eye - at);
                const double cosEye = glm::dot(toEye, front);
                const double cosEyeInside = refractedCosine(cosEye, marble.eta);
                const double cosLight = -glm::dot(towardsLight, front);
                const double cosLightInside = refractedCosine(cosLight, marble.eta);
                const double geometry =
                    singleScatteringGeometry(towardsLight, -front, toEye, front, marble.eta, 0.0) *
                    irradiance;
                Rgb sigmaS{}, sigmaT{};
                for (int c = 0; c < 3; ++c) {
                    sigmaS[c] = (*marble.sigmaSPrime)[c];
                    sigmaT[c] = sigmaS[c] + (*marble.sigmaA)[c];
                }
                // The pass's own rule (midpoint strata) on the exact slab: a sample s along the
                // refracted view ray lies s cos θo′ below the front face; the light reaches it
                // through the back face, (d − s cos θo′)/cos θi′ of refracted path away.
                const Rgb rule = estimateSingleScattering(
                    sigmaS, sigmaT, kSlabSamples, {0.5, 0.5, 0.5}, [&](double s) {
                        const double below = s * cosEyeInside;
                        return below > slab.thickness
                                   ? LightAtSample{}
                                   : LightAtSample{geometry,
                                                   (slab.thickness - below) / cosLightInside};
                    });
                const Rgb& gpu = slab.single[static_cast<std::size_t>(y) * 32 + x];
                for (int c = 0; c < 3; ++c) {
                    ScatteringMedium medium{sigmaS[c], (*marble.sigmaA)[c], marble.eta, 0.0};
                    const double closed = backLitSlabRadiance(medium, front, towardsLight, toEye,
                                                              irradiance, slab.thickness);
                    ASSERT_GT(closed, 0.0);
                    // The GPU against its rule: the reconstructed faces lie within a fraction
                    // of the point spacing (a twentieth of the thinnest slab) of the true ones,
                    // and the term is a half float: 2 % (measured: at most 0.8 %).
                    EXPECT_NEAR(gpu[c], rule[c], 0.02 * rule[c])
                        << paths << " free paths, pixel " << x << "," << y << " channel " << c;
                    // Against the closed form: the rule's own quadrature error (a midpoint rule
                    // across the back face's cut-off, computed here in double) plus those 2 %.
                    const double quadrature = std::abs(rule[c] - closed) / closed;
                    EXPECT_NEAR(gpu[c], closed, (quadrature + 0.02) * closed)
                        << paths << " free paths, pixel " << x << "," << y << " channel " << c;
                    // Measured: 3.2 % at half a free path, 0.7 % at two.
                    EXPECT_LT(quadrature, 0.05) << "the rule itself is within 5 %";
                }
                ++checked;
            }
        }
        EXPECT_EQ(checked, 256);
    }
}

TEST(LightMapsGLTest, SlabLitFromBehindGetsNothingThroughTheScreenMarch) {
    // The documented fallback: the march through the camera's depth looks for the entry on
    // surfaces the camera sees; the back face is none, so the light behind adds nothing.
    const glm::dvec3 towardsLight = glm::normalize(glm::dvec3(0.4, 0.2, -1.0));
    const BackLitSlab slab = renderBackLitSlab(0.38, towardsLight, LightPath::Screen);
    for (int y = 8; y < 24; ++y) {
        for (int x = 8; x < 24; ++x) {
            const Rgb& value = slab.single[static_cast<std::size_t>(y) * 32 + x];
            EXPECT_EQ(value[0] + value[1] + value[2], 0.0) << x << "," << y;
        }
    }
    const BackLitSlab mapped = renderBackLitSlab(0.38, towardsLight, LightPath::LightMap);
    EXPECT_GT(mapped.single[16 * 32 + 16][1], 0.0);
}

/// A plate of marble points 16 mm wide in the plane z = 0 (millimetres), seen θo from its
/// normal and lit by one directional light θi from it on the other side of the normal (the
/// plane of incidence is the camera's): single scattering alone, per pixel, and where each
/// pixel's ray meets the plate.
struct FrontLitPlate {
    std::vector<Rgb> single;
    std::vector<std::optional<glm::dvec3>> hit;
    Camera camera;
    glm::dvec3 towardsLight;
};

constexpr double kPlateSpacing = 0.04;  // mm: about 3 points across a pixel of the camera below
constexpr int kPlatePixels = 48;

const PointCloud& marblePlate() {
    static const PointCloud plate = [] {
        PointCloudBuilder builder({.color = true}, 170000);
        addPlate(builder, 0.0, 16.0, {0.0, 0.0}, 0.0, Facing::Z, kPlateSpacing);
        return finish(builder);
    }();
    return plate;
}

FrontLitPlate renderFrontLitPlate(double lightDegrees, double viewDegrees, float g,
                                  LightPath path) {
    Renderer renderer(test::glTestContext(), marblePlate(), kPlateSpacing);
    const double light = glm::radians(lightDegrees), view = glm::radians(viewDegrees);
    const glm::dvec3 towardsLight(0.0, -std::sin(light), std::cos(light));
    const RenderSettings settings = marbleSingleScattering(towardsLight, path, g);
    // 6 mm seen from 40 mm: a pixel is 0.125 mm, a third of marble's mean free path, so that
    // where in its pixel the reconstruction puts the surface matters.
    Camera camera;
    camera.width = camera.height = kPlatePixels;
    constexpr double kDistance = 40.0;
    camera.fovyDegrees = glm::degrees(2.0 * std::atan(3.0 / kDistance));
    camera.view = glm::lookAt(kDistance * glm::dvec3(0.0, std::sin(view), std::cos(view)),
                              glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
    camera.nearPlane = kDistance - 20.0;
    camera.farPlane = kDistance + 20.0;
    renderer.render(camera, settings, FrameOutputs::Everything);
    FrontLitPlate result{{}, {}, camera, towardsLight};
    const std::vector<float> rgba = renderer.resources().texture("singleScattering").readFloats();
    for (std::size_t i = 0; i < rgba.size(); i += 4) {
        result.single.push_back({rgba[i], rgba[i + 1], rgba[i + 2]});
    }
    for (int y = 0; y < kPlatePixels; ++y) {
        for (int x = 0; x < kPlatePixels; ++x) {
            result.hit.push_back(hitPlane(pixelRay(camera, x, y), 0.0, 2));
        }
    }
    return result;
}

/// The middle half of the picture's pixels: each channel's ratio of the pass's single
/// scattering to the semi-infinite slab's closed form at that pixel's own angles.
std::vector<double> ratiosToTheClosedForm(const FrontLitPlate& plate, float g) {
    const Material& marble = measuredMaterial("marble");
    const glm::dvec3 front(0.0, 0.0, 1.0);
    const glm::dvec3 eye = plate.camera.eye();
    std::vector<double> ratios;
    for (int y = kPlatePixels / 4; y < 3 * kPlatePixels / 4; ++y) {
        for (int x = kPlatePixels / 4; x < 3 * kPlatePixels / 4; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * kPlatePixels + x;
            const glm::dvec3 toEye = glm::normalize(eye - *plate.hit[i]);
            for (int c = 0; c < 3; ++c) {
                const ScatteringMedium medium{(*marble.sigmaSPrime)[c] / (1.0 - g),
                                              (*marble.sigmaA)[c], marble.eta, g};
                const double closed = semiInfiniteSlabRadiance(medium, front, plate.towardsLight,
                                                               toEye, std::numbers::pi);
                ratios.push_back(plate.single[i][c] / closed);
            }
        }
    }
    return ratios;
}

double median(std::vector<double> values) {
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    return values[values.size() / 2];
}

TEST(LightMapsGLTest, FrontLitPlateMatchesTheClosedFormThroughTheLightMap) {
    // Both paths to the entry against the semi-infinite slab's closed form, at angle pairs
    // where the camera's and the light's reconstructions place the plate differently within
    // their pixels (before the registration, lightMapRegistration, the map's medians were
    // 1.11 / 0.97 / 1.12 / 1.04 / 1.06 at g = 0 and 1.20 / 0.95 / 1.23 / 1.08 / 1.12 at g = 0.5).
    for (const float g : {0.0f, 0.5f}) {
        for (const auto& [light, view] :
             {std::pair{0.0, 60.0}, {60.0, 0.0}, {30.0, 60.0}, {60.0, 30.0}, {30.0, 30.0}}) {
            for (const LightPath path : {LightPath::Screen, LightPath::LightMap}) {
                const std::vector<double> ratios =
                    ratiosToTheClosedForm(renderFrontLitPlate(light, view, g, path), g);
                const auto [low, high] = std::minmax_element(ratios.begin(), ratios.end());
                const char* name = path == LightPath::Screen ? "screen" : "light map";
                // One tolerance for both paths, what the screen march meets. The median: 3 %
                // (measured: the march within 0.8 %; the map within 2.3 %, at θi = 30° where
                // its texels hold one or two points in a beat along the tilt, so that its
                // surface's offset from the truth varies over a few texels). Each pixel: 7 %
                // (measured: the march 0.94..1.03, the map 0.96..1.05), where the 63 samples'
                // entries cross the camera's pixels and the map's texels unevenly.
                EXPECT_NEAR(median(ratios), 1.0, 0.03)
                    << name << " g " << g << " θi " << light << " θo " << view;
                EXPECT_GT(*low, 0.93) << name << " g " << g << " θi " << light << " θo " << view;
                EXPECT_LT(*high, 1.07) << name << " g " << g << " θi " << light << " θo " << view;
            }
        }
    }
}

/// The diffuse light (before the blur) in the middle of a slab of skin between two plates of
/// points 6 mm wide (millimetres), seen from the front, lit by one directional light.
constexpr double kTransmissionSpacing = 0.05;  // mm: a tenth of the thinnest slab

std::vector<float> transmittedDiffuse(double thickness, const glm::dvec3& towardsLight,
                                      bool transmission,
                                      float shadowBias = ShadingSettings{}.shadowBias) {
    Renderer renderer(test::glTestContext(), slab(thickness, 6.0, kTransmissionSpacing),
                      kTransmissionSpacing);
    RenderSettings settings = lightOnly(towardsLight);
    settings.raster.mode = RenderMode::Sss;
    settings.scattering.material = "skin-deon";
    settings.scattering.unit = SceneUnit::Millimetre;
    settings.scattering.transmission = transmission;
    settings.shading.shadowBias = shadowBias;
    Camera camera;
    camera.width = camera.height = 16;
    camera.fovyDegrees = 10.0;
    camera.view = glm::lookAt(glm::dvec3(0.0, 0.0, 12.0), glm::dvec3(0.0), glm::dvec3(0, 1, 0));
    camera.nearPlane = 5.0;
    camera.farPlane = 30.0;
    renderer.render(camera, settings, FrameOutputs::Everything);
    return renderer.resources().texture("diffuse").readFloats();
}

/// The green diffuse light at the middle pixel, and the brightest of the middle 8².
float middlePixel(const std::vector<float>& diffuse) {
    return diffuse[4 * (8 * 16 + 8) + 1];
}
float brightestInTheMiddle(const std::vector<float>& diffuse) {
    float brightest = 0.0f;
    for (int y = 4; y < 12; ++y) {
        for (int x = 4; x < 12; ++x) {
            brightest = std::max(brightest, diffuse[4 * (y * 16 + x) + 1]);
        }
    }
    return brightest;
}

TEST(LightMapsGLTest, TransmissionThroughASlabFollowsTheProfile) {
    const GaussianSet& profile = findMaterial("skin-deon").gaussians;
    const glm::dvec3 behind = glm::normalize(glm::dvec3(0.3, 0.2, -1.0));
    const auto transmitted = [&](double thickness) {
        // T(t) = Σ w_i e^(−t²/2v_i): the profile integrated over the plane t deep; a white
        // plate, a light of value 1 arriving at cos θ = −z.
        double through = 0.0;
        for (const Gaussian& term : profile.gaussians) {
            through += term.weight[1] * std::exp(-thickness * thickness / (2.0 * term.varianceMm2));
        }
        return -behind.z * through;
    };
    // A light-map texel (about h wide) holds its nearest point: the back face lies up to half
    // a texel's slope, h tan θ / 2, nearer the light than the truth; the diffuse light is a
    // half float besides (1 %).
    const double tangent = std::sqrt(1.0 - behind.z * behind.z) / -behind.z;
    const double slack = 0.5 * kTransmissionSpacing * tangent;
    for (const double thickness : {0.5, 1.0, 2.0}) {
        const double value = middlePixel(transmittedDiffuse(thickness, behind, true));
        EXPECT_GE(value, 0.99 * transmitted(thickness + slack)) << thickness << " mm";
        EXPECT_LE(value, 1.01 * transmitted(thickness)) << thickness << " mm";
        EXPECT_EQ(brightestInTheMiddle(transmittedDiffuse(thickness, behind, false)), 0.0f)
            << thickness << " mm";
    }
    // Lit from the front, the front face is the light's own first surface: Lambert alone.
    const glm::dvec3 front = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
    // The diffuse light is a half float: 11 significant bits, 5e-4 of 0.95.
    EXPECT_NEAR(brightestInTheMiddle(transmittedDiffuse(0.5, front, true)), front.z, 0.002);
    // Also with no shadow bias at all: the fade keeps a texel's tolerance.
    EXPECT_NEAR(brightestInTheMiddle(transmittedDiffuse(0.5, front, true, 0.0f)), front.z, 0.002);
}

TEST(LightMapsGLTest, LightMapHoldsTheDepthOfThePlaneItSees) {
    PointCloudBuilder builder({.color = true}, 50000);
    addPlate(builder, 0.0, 1.0, {0.0, 0.0});
    Renderer renderer(test::glTestContext(), finish(builder), kSpacing);
    const glm::dvec3 towardsLight = glm::normalize(glm::dvec3(0.3, 1.0, 0.5));
    const Camera camera = lookingAt({0.0, 1.6, 1.6}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    renderer.render(camera, lightOnly(towardsLight));
    ASSERT_EQ(renderer.lightMaps().maps().size(), 1u);
    const LightMaps::Map& map = renderer.lightMaps().maps().front();
    ASSERT_TRUE(map.camera.orthographic());
    const std::vector<float> texels = map.texture.readFloats();
    const double texel = 1.0 / map.camera.focalLengthPixels();
    const double tangent = std::sqrt(1.0 - towardsLight.y * towardsLight.y) / towardsLight.y;
    const glm::dmat4 worldFromLight = glm::inverse(map.camera.view);
    const glm::dvec3 along = glm::dvec3(worldFromLight * glm::dvec4(0.0, 0.0, -1.0, 0.0));
    std::size_t onPlate = 0, wrong = 0, spilled = 0;
    for (int j = 0; j < map.camera.height; ++j) {
        for (int i = 0; i < map.camera.width; ++i) {
            const glm::dvec3 start(
                worldFromLight * glm::dvec4((i + 0.5 - 0.5 * map.camera.width) * texel,
                                            (0.5 * map.camera.height - j - 0.5) * texel, 0.0, 1.0));
            const std::optional<glm::dvec3> p = hitPlane({start, along}, 0.0);
            const std::size_t t = static_cast<std::size_t>(j) * map.camera.width + i;
            const float stored = texels[4 * t];
            if (p && insideSquare(*p, {0.0, 0.0}, 1.0, 2.0 * kSpacing)) {
                ++onPlate;
                const double expected = glm::length(*p - start);
                // The nearest point in a texel lies anywhere inside it: within half a texel
                // along each axis of the plane's depth at the centre (the plane's slope is
                // tan θ per unit across the light), plus float rounding.
                wrong += std::abs(stored - expected) > texel * tangent + 1e-4 ? 1 : 0;
            } else if (!p || !insideSquare(*p, {0.0, 0.0}, 1.0, -2.0 * kSpacing)) {
                spilled += std::isinf(stored) ? 0 : 1;  // 2 h beyond the plate: nothing
            }
        }
    }
    EXPECT_GT(onPlate, 20000u);
    EXPECT_EQ(wrong, 0u) << "of " << onPlate << " texels on the plate";
    EXPECT_EQ(spilled, 0u);
}

TEST(LightMapsGLTest, MapsAreRebuiltOnlyWhenTheirLightOrItsSettingsChange) {
    PointCloudBuilder builder({.color = true}, 50000);
    addPlate(builder, 0.0, 1.0, {0.0, 0.0});
    Renderer renderer(test::glTestContext(), finish(builder), kSpacing);
    RenderSettings settings = lightOnly({0.3, 1.0, 0.5});
    Camera camera = lookingAt({0.0, 1.6, 1.6}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    const LightMaps& maps = renderer.lightMaps();

    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 1u);
    const FrameResult moved =
        renderer.render(lookingAt({0.9, 1.2, 1.4}, {0.1, 0.0, 0.0}, {0.0, 1.0, 0.0}), settings);
    EXPECT_EQ(maps.builds(), 1u) << "moving the camera must not rebuild a light map";
    for (const PassTiming& timing : moved.passes) {
        EXPECT_NE(timing.pass.rfind("LightMap.", 0), 0u) << timing.pass << " ran";
    }
    settings.shading.headLight = glm::vec3(0.5f);  // shading, not the map
    renderer.render(camera, settings, FrameOutputs::Everything);
    EXPECT_EQ(maps.builds(), 1u);

    settings.shading.lights[0].direction = glm::vec3(-0.3f, 1.0f, 0.5f);
    const FrameResult turned = renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 2u) << "turning the light must rebuild its map";
    EXPECT_EQ(turned.passes.front().pass, "LightMap.RasterizePoints");

    settings.shading.lights.push_back({glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.5f)});
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 3u) << "a second light gets its own map; the first is kept";

    settings.surface.visibilityThreshold = 0.25f;
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 5u) << "a surface setting reshapes both maps";

    settings.raster.normalBlend = 2.0f;
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 7u) << "the maps keep the blended normals";

    settings.shading.lightMapResolution = 128;
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 9u);
    EXPECT_EQ(std::max(maps.maps()[0].camera.width, maps.maps()[0].camera.height),
              128 + 2 * kLightMapMargin);

    settings.shading.shadows = false;
    renderer.render(camera, settings);
    settings.raster.mode = RenderMode::Points;
    settings.shading.shadows = true;
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 9u) << "frames without shadows build no map";

    // A light fixed to the view turns with the camera: its map follows, the other's stays.
    settings.raster.mode = RenderMode::Surface;
    settings.shading.lights[1].space = LightSpace::View;
    settings.shading.lights[1].direction = glm::vec3(-0.5f, 0.5f, 0.7f);
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 10u);
    renderer.render(camera, settings);
    EXPECT_EQ(maps.builds(), 10u);
    renderer.render(lookingAt({0.9, 1.2, 1.4}, {0.1, 0.0, 0.0}, {0.0, 1.0, 0.0}), settings);
    EXPECT_EQ(maps.builds(), 11u);
}

TEST(LightMapsGLTest, ALightFixedToTheViewShadesLikeTheSameLightInTheScene) {
    PointCloudBuilder builder({.color = true}, 170000);
    addPlate(builder, 0.0, 2.0, {0.0, 0.0});
    addPlate(builder, 0.6, 0.6, {0.35, 0.0});
    Renderer renderer(test::glTestContext(), finish(builder), kSpacing);
    const Camera camera = lookingAt({0.4, 2.5, 1.5}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
    const glm::dvec3 inView(-0.4, 0.6, 0.5);
    RenderSettings settings = lightOnly(inView);
    settings.shading.lights[0].space = LightSpace::View;
    const Shaded viewLight = renderShaded(renderer, camera, settings);
    settings.shading.lights[0].space = LightSpace::World;
    settings.shading.lights[0].direction =
        glm::vec3(glm::transpose(glm::dmat3(camera.view)) * glm::normalize(inView));
    const Shaded sceneLight = renderShaded(renderer, camera, settings);
    ASSERT_EQ(viewLight.radiance.size(), sceneLight.radiance.size());
    std::size_t different = 0;
    for (std::size_t i = 0; i < viewLight.radiance.size(); ++i) {
        // The same direction up to float rounding of its two routes: 1e-3 of a unit radiance.
        different += std::abs(viewLight.radiance[i] - sceneLight.radiance[i]) > 1e-3f ? 1 : 0;
    }
    EXPECT_EQ(different, 0u);
}

}  // namespace
}  // namespace subscan
