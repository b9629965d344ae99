// Shading under directional lights against the CPU formula (DESIGN.md §5.6): Lambert plus
// Blinn-Phong with the halfway vector of each light and the eye, the scene's light directions
// turned into view space by the camera's rotation. The head light alone cannot tell the
// halfway vector from the view vector (they coincide), nor a wrong world-to-view transform.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "core/Camera.h"
#include "render/Renderer.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

TEST(ShadeGLTest, DirectionalLightsFollowLambertAndBlinnPhongInViewSpace) {
    const PointCloud cloud = makeSyntheticScene("sphere?points=20000");
    Renderer renderer(test::glTestContext(), cloud);
    // An orbit from the side and above: the view's rotation is far from the identity.
    const Camera camera = orbitCamera(cloud.bounds, {70.0, 35.0}, 96, 80, 45.0);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.shading.headLight = glm::vec3(0.2f);
    settings.shading.ambient = glm::vec3(0.05f);
    settings.shading.specular = 0.3f;
    settings.shading.shininess = 20.0f;
    settings.shading.shadows = false;  // a sphere shades itself; shadows are LightMapsGLTest's
    settings.shading.lights = {{{1.0f, 0.4f, -0.3f}, {0.9f, 0.6f, 0.3f}, LightSpace::World},
                               {{-0.2f, 0.3f, 1.0f}, {0.2f, 0.5f, 0.7f}, LightSpace::View}};
    renderer.render(camera, settings, FrameOutputs::Everything);
    const FrameResources& resources = renderer.resources();
    const auto depth = resources.texture("surfaceDepth").readFloats();
    const auto normals = resources.texture("normals").readFloats();
    const auto albedo = resources.texture("filledColor").readFloats();
    const auto radiance = resources.texture("radiance").readFloats();

    // The lights towards which the surface faces, in view space.
    std::vector<glm::dvec3> towards;
    for (const DirectionalLight& light : settings.shading.lights) {
        const glm::dvec3 world = glm::normalize(glm::dvec3(light.direction));
        towards.push_back(light.space == LightSpace::View
                              ? world
                              : glm::normalize(glm::dmat3(camera.view) * world));
    }
    const double f = camera.focalLengthPixels();
    int checked = 0;
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const int i = y * camera.width + x;
            if (std::isinf(depth[i])) {
                continue;
            }
            const glm::dvec3 position(depth[i] * (x + 0.5 - 0.5 * camera.width) / f,
                                      depth[i] * (0.5 * camera.height - y - 0.5) / f, -depth[i]);
            const glm::dvec3 toEye = glm::normalize(-position);
            const glm::dvec3 n(normals[4 * i], normals[4 * i + 1], normals[4 * i + 2]);
            glm::dvec3 irradiance(settings.shading.ambient);
            glm::dvec3 specular(0.0);
            const auto add = [&](const glm::dvec3& toLight, const glm::dvec3& value) {
                const double cosine = glm::dot(n, toLight);
                if (cosine <= 0.0) {
                    return;
                }
                const glm::dvec3 halfway = glm::normalize(toLight + toEye);
                irradiance += value * cosine;
                specular += value * cosine * double(settings.shading.specular) *
                            std::pow(std::max(glm::dot(n, halfway), 0.0),
                                     double(settings.shading.shininess));
            };
            add(toEye, glm::dvec3(settings.shading.headLight));
            for (std::size_t l = 0; l < towards.size(); ++l) {
                add(towards[l], glm::dvec3(settings.shading.lights[l].radiance));
            }
            for (int c = 0; c < 3; ++c) {
                const double a = std::clamp(double(albedo[4 * i + c]), 0.0, 1.0);
                const double expected = a * irradiance[c] + specular[c];
                // RGBA16F radiance: 11 significant bits, ~5e-4 relative.
                EXPECT_NEAR(radiance[4 * i + c], expected, 2e-3 * (1.0 + expected))
                    << x << "," << y << " channel " << c;
            }
            ++checked;
        }
    }
    EXPECT_GT(checked, 1000);
}

}  // namespace
}  // namespace subscan
