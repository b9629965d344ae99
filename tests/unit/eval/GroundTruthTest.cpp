#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "eval/GroundTruth.h"
#include "scan/Scene.h"
#include "support/TestScenes.h"

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

/// Linear depth at which the ray from `eye` through window position (wx, wy) meets y = 0;
/// infinite where it does not.
double planeDepthAt(const Camera& camera, double wx, double wy) {
    const double f = camera.focalLengthPixels();
    const glm::dvec3 view((wx - 0.5 * camera.width) / f, (0.5 * camera.height - wy) / f, -1.0);
    const glm::dvec3 world = glm::dvec3(glm::inverse(camera.view) * glm::dvec4(view, 0.0));
    const glm::dvec3 eye = camera.eye();
    return world.y < 0.0 ? -eye.y / world.y : std::numeric_limits<double>::infinity();
}

TEST(GroundTruthTest, TheDepthWithinAPixelIsTheTruePlanesAtItsCornersUpToTheSteepestSlope) {
    // The plane (wider than the views reach) seen from 2 m above at pitches from steep to grazing:
    // near the horizon its depth changes by more than 8 pixel widths across a pixel and the cap
    // holds.
    for (const double pitchDegrees : {80.0, 30.0, 5.0}) {
        Camera camera;
        camera.width = 48;
        camera.height = 40;
        camera.fovyDegrees = 40.0;
        camera.nearPlane = 0.05;
        camera.farPlane = 1000.0;
        const double pitch = pitchDegrees * std::numbers::pi / 180.0;
        const glm::dvec3 eye(0.0, 2.0, 0.0);
        camera.view = glm::lookAt(eye, eye + glm::dvec3(0.0, -std::sin(pitch), -std::cos(pitch)),
                                  glm::dvec3(0, 1, 0));
        const GroundTruthImages images = renderGroundTruth(test::GroundRectangle(1e4), camera);
        const double f = camera.focalLengthPixels();
        int capped = 0, measured = 0;
        for (int y = 0; y < camera.height; ++y) {
            for (int x = 0; x < camera.width; ++x) {
                const std::size_t i = static_cast<std::size_t>(y * camera.width + x);
                if (std::isinf(images.depth[i])) {
                    EXPECT_EQ(images.depthWithinPixel[i], 0.0f) << x << "," << y;
                    continue;
                }
                const double centre = planeDepthAt(camera, x + 0.5, y + 0.5);
                double farthest = 0.0;
                for (const int cx : {0, 1}) {
                    for (const int cy : {0, 1}) {
                        farthest = std::max(
                            farthest, std::abs(planeDepthAt(camera, x + cx, y + cy) - centre));
                    }
                }
                const double cap = kSteepestDepthWithinPixel * centre / f;
                capped += farthest >= cap;
                ++measured;
                // float storage of values up to ~8 m / 55 px: relative 1e-6, and the ray
                // tracer's hit to 1e-9 of the distance.
                EXPECT_NEAR(images.depthWithinPixel[i], std::min(farthest, cap),
                            1e-5 * std::min(farthest, cap) + 1e-7)
                    << pitchDegrees << "° " << x << "," << y;
            }
        }
        EXPECT_GT(measured, 100) << pitchDegrees;
        if (pitchDegrees < 10.0) {
            EXPECT_GT(capped, 0) << "near the horizon the cap must be reached";
        } else {
            EXPECT_EQ(capped, 0) << pitchDegrees;
        }
    }
}

}  // namespace
}  // namespace subscan
