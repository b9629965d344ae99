#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/Camera.h"

namespace subscan {
namespace {

Bounds box(glm::dvec3 min, glm::dvec3 max) {
    Bounds bounds;
    bounds.add(min);
    bounds.add(max);
    return bounds;
}

TEST(CameraTest, AutoFramingKeepsEveryCornerInsideTheImageAndDepthRange) {
    const Bounds bounds = box({500000, 5400000, 10}, {500040, 5400010, 25});
    for (const double yaw : {0.0, 45.0, 200.0}) {
        for (const double pitch : {-60.0, 0.0, 35.0, 90.0}) {
            for (const UpAxis up : {UpAxis::Y, UpAxis::Z}) {
                const Camera camera =
                    orbitCamera(bounds, {yaw, pitch, std::nullopt, up}, 160, 90, 45);
                for (int corner = 0; corner < 8; ++corner) {
                    const glm::dvec3 p((corner & 1) ? bounds.max.x : bounds.min.x,
                                       (corner & 2) ? bounds.max.y : bounds.min.y,
                                       (corner & 4) ? bounds.max.z : bounds.min.z);
                    const glm::dvec4 view = camera.view * glm::dvec4(p, 1.0);
                    const glm::dvec4 clip = camera.projection() * view;
                    EXPECT_GT(-view.z, camera.nearPlane);
                    EXPECT_LT(-view.z, camera.farPlane);
                    EXPECT_LE(std::abs(clip.x / clip.w), 1.0);
                    EXPECT_LE(std::abs(clip.y / clip.w), 1.0);
                }
            }
        }
    }
}

TEST(CameraTest, YawZeroLooksAtTheFront) {
    const Bounds bounds = box({-1, -1, -1}, {1, 1, 1});
    const Camera yUp = orbitCamera(bounds, {0, 0, 10.0, UpAxis::Y}, 100, 100, 40);
    const glm::dvec3 eyeY = yUp.eye();
    // Double-precision lookAt: 1e-12 is far below anything that matters.
    EXPECT_NEAR(eyeY.x, 0, 1e-12);
    EXPECT_NEAR(eyeY.y, 0, 1e-12);
    EXPECT_NEAR(eyeY.z, 10, 1e-12);
    const Camera zUp = orbitCamera(bounds, {0, 0, 10.0, UpAxis::Z}, 100, 100, 40);
    EXPECT_NEAR(zUp.eye().y, -10, 1e-12);
    // Z-up data keeps +Z pointing up in the image: view-space y of (0,0,1) is positive.
    EXPECT_GT((zUp.view * glm::dvec4(0, 0, 1, 0)).y, 0.99);
}

TEST(CameraTest, FocalLengthMatchesTheProjection) {
    Camera camera;
    camera.width = 200;
    camera.height = 100;
    camera.fovyDegrees = 60;
    // A point 1 unit up at depth f/50 lands 50 pixels above the centre: f = H / (2 tan 30°).
    EXPECT_NEAR(camera.focalLengthPixels(), 100 / (2 * std::tan(glm::radians(30.0))), 1e-12);
    const glm::dvec4 clip =
        camera.projection() * glm::dvec4(0, 1, -camera.focalLengthPixels() / 50, 1);
    EXPECT_NEAR(clip.y / clip.w * 50.0, 50.0, 1e-9);
}

}  // namespace
}  // namespace subscan
