#include <cmath>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>

#include "eval/GroundTruth.h"
#include "scan/Scene.h"

namespace subscan {
namespace {

TEST(GroundTruthTest, UnitSphereSeenFromTheFront) {
    const auto sphere = makeBuiltInScene("sphere");
    Camera camera;
    camera.width = 41;
    camera.height = 31;
    camera.fovyDegrees = 40.0;
    camera.nearPlane = 0.5;
    camera.farPlane = 20.0;
    camera.view = glm::lookAt(glm::dvec3(0, 0, 5), glm::dvec3(0), glm::dvec3(0, 1, 0));
    const GroundTruthImages images = renderGroundTruth(*sphere, camera);
    const double f = camera.focalLengthPixels();
    int covered = 0;
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y * camera.width + x);
            // The pixel centre's ray, and where it meets the unit sphere analytically.
            const glm::dvec3 d = glm::normalize(glm::dvec3(
                (x + 0.5 - 0.5 * camera.width) / f, (0.5 * camera.height - (y + 0.5)) / f, -1.0));
            const double b = glm::dot(glm::dvec3(0, 0, 5), d);
            const double discriminant = b * b - (25.0 - 1.0);
            if (discriminant < 0.0) {
                EXPECT_TRUE(std::isinf(images.depth[i])) << x << "," << y;
                continue;
            }
            ++covered;
            const double t = -b - std::sqrt(discriminant);
            const glm::dvec3 hit = glm::dvec3(0, 0, 5) + t * d;
            // Float depth of a value ~4: ~5e-7; the sphere tracer refines to 1e-11 of the size.
            EXPECT_NEAR(images.depth[i], 5.0 - hit.z, 1e-5) << x << "," << y;
            // View space equals world space up to the translation here.
            EXPECT_LT(glm::length(glm::dvec3(images.normals[i]) - hit), 1e-4) << x << "," << y;
        }
    }
    EXPECT_GT(covered, 100);
}

}  // namespace
}  // namespace subscan
