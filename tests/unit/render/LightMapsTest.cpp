// A directional light's orthographic view (lightCamera): it holds the cloud's bounds with the
// filter's margin, at the resolution asked for, looking along the light.
#include <algorithm>

#include <gtest/gtest.h>
#include <glm/matrix.hpp>

#include "render/LightMaps.h"

namespace subscan {
namespace {

TEST(LightMapsTest, LightCameraHoldsTheBoundsWithItsMargin) {
    Bounds bounds;
    bounds.add({-1.0, 2.0, 10.0});
    bounds.add({3.0, 2.5, 11.0});
    for (const glm::dvec3& towardsLight :
         {glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(1.0, 0.2, -0.3), glm::dvec3(0.0, -1.0, 0.0)}) {
        const Camera camera = lightCamera(bounds, towardsLight, 300, 0.01);
        ASSERT_TRUE(camera.orthographic());
        EXPECT_EQ(std::max(camera.width, camera.height), 300 + 2 * kLightMapMargin);
        const glm::dmat4 projection = camera.projection();
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 p = bounds.corner(corner);
            const glm::dvec4 view = camera.view * glm::dvec4(p, 1.0);
            const glm::dvec4 clip = projection * view;
            const double x = (clip.x / clip.w + 1.0) * 0.5 * camera.width;
            const double y = (1.0 - clip.y / clip.w) * 0.5 * camera.height;
            // The margin less a hair for rounding the box's extent up to whole texels.
            EXPECT_GE(x, kLightMapMargin - 1e-6);
            EXPECT_LE(x, camera.width - kLightMapMargin + 1e-6);
            EXPECT_GE(y, kLightMapMargin - 1e-6);
            EXPECT_LE(y, camera.height - kLightMapMargin + 1e-6);
            EXPECT_GT(-view.z, camera.nearPlane);
            EXPECT_LT(-view.z, camera.farPlane);
        }
        // The camera looks along -towardsLight.
        const glm::dvec3 forward = -glm::dvec3(glm::inverse(camera.view)[2]);
        EXPECT_NEAR(glm::dot(forward, -glm::normalize(towardsLight)), 1.0, 1e-9);
    }
}

TEST(LightMapsTest, AutomaticResolutionIsOneTexelPerSpacingWithinItsLimits) {
    Bounds bounds;
    bounds.add({0.0, 0.0, 0.0});
    bounds.add({1.0, 1.0, 1.0});
    const glm::dvec3 down(0.0, 1.0, 0.0);  // the light sees the 1 x 1 square
    EXPECT_EQ(std::max(lightCamera(bounds, down, 0, 0.002).width,
                       lightCamera(bounds, down, 0, 0.002).height),
              500 + 2 * kLightMapMargin);
    EXPECT_EQ(lightCamera(bounds, down, 0, 1e-5).width, 2048 + 2 * kLightMapMargin);
    EXPECT_EQ(lightCamera(bounds, down, 0, 0.5).width, 64 + 2 * kLightMapMargin);
}

}  // namespace
}  // namespace subscan
