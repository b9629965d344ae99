// A close-up where the surface fills the whole frame: every pixel, the image's border included,
// shows the front surface, with gaps between its points and a second surface behind it whose
// points fall into those gaps. At the border neither hidden point removal nor fill removal can
// see past the image: they must not treat that as open space.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "core/Camera.h"
#include "render/Renderer.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

constexpr double kSpacing = 0.02;    // between the grid points of each plane
constexpr double kFrontDepth = 0.5;  // the eye looks at the front plane from here
constexpr double kBackOffset = 0.5;  // the back plane lies this much further
// Along the border, walks of the hidden point test are cut short: up to two texels of the
// coarsest level it walks for the back plane (level 2 at depth 1: 2 x 4 pixels).
constexpr int kBand = 8;

/// Two parallel planes of jittered grid points, the back one shifted by half a spacing so that
/// its points land between the front's on screen.
PointCloud twoPlanes() {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    PointCloudBuilder builder({}, 2 * 81 * 101);
    for (int plane = 0; plane < 2; ++plane) {
        const double shift = plane == 0 ? 0.0 : 0.5;
        const double z = plane == 0 ? 0.0 : -kBackOffset;
        for (int j = -40; j <= 40; ++j) {
            for (int i = -50; i <= 50; ++i) {
                PointRecord point;
                point.position = {(i + shift + jitter(random)) * kSpacing,
                                  (j + shift + jitter(random)) * kSpacing, z};
                builder.add(point);
            }
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

TEST(SurfaceCloseUpGLTest, TheFrontSurfaceReachesEveryPixelOfTheBorder) {
    const PointCloud cloud = twoPlanes();
    Renderer renderer(test::glTestContext(), cloud, kSpacing);
    Camera camera;
    camera.width = 61;
    camera.height = 43;
    camera.nearPlane = 0.05;
    camera.farPlane = 5.0;
    // At depth 0.5 the view spans +-0.21 vertically and +-0.29 horizontally, well inside the
    // planes (+-0.8 and +-1.0): points lie about 2.2 pixels apart, with gaps between them.
    camera.view =
        glm::lookAt(glm::dvec3(0.0, 0.0, kFrontDepth), glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    renderer.render(camera, settings);
    const std::vector<float> depth = renderer.resources().texture("surfaceDepth").readFloats();
    ASSERT_EQ(depth.size(), static_cast<std::size_t>(camera.width * camera.height));
    int band = 0, backInBand = 0;
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const float value = depth[y * camera.width + x];
            ASSERT_TRUE(std::isfinite(value)) << "pixel " << x << "," << y << " lost";
            // Pull-push interpolates between points of the front plane, all at depth 0.5; a
            // tenth of the gap to the back plane separates "front" from "back showing through".
            const bool back = std::abs(value - kFrontDepth) > 0.1 * kBackOffset;
            const int fromBorder = std::min({x, y, camera.width - 1 - x, camera.height - 1 - y});
            if (fromBorder >= kBand) {
                EXPECT_FALSE(back) << "pixel " << x << "," << y;
            } else {
                ++band;
                backInBand += back;
            }
        }
    }
    // There the test cannot see what lies beyond the border, and a point of the back plane
    // next to others of its kind may pass as visible. Counting cut walks in full let 15 % of
    // this band show the back plane; weighing them by the levels they saw, 2.6 %.
    EXPECT_LT(backInBand, band / 20);
}

/// Ground as a jittered grid (spacing kGroundSpacing, +-0.3 of it) of kGroundHalfSize either way
/// about the origin, in the plane y = 0.
constexpr double kGroundSpacing = 0.16;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kGroundHalfSize = 20.0;

PointCloud ground() {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> jitter(-0.3, 0.3);
    const int half = static_cast<int>(kGroundHalfSize / kGroundSpacing);
    PointCloudBuilder builder({}, (2 * half + 1) * (2 * half + 1));
    for (int j = -half; j <= half; ++j) {
        for (int i = -half; i <= half; ++i) {
            PointRecord point;
            point.position = {(i + jitter(random)) * kGroundSpacing, 0.0,
                              (j + jitter(random)) * kGroundSpacing};
            builder.add(point);
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

// Ground seen from above at a slant runs off the image's bottom border. Near the eye its points
// lie several pixels apart along their rows but the rows closer on screen, so below a gap near
// the border the points lie beside its downward cone: the border must count where the points
// reach it, or holes show just above it (Autzen's ground alike).
TEST(SurfaceCloseUpGLTest, GroundRunningOffTheBottomBorderHasNoHoles) {
    const PointCloud cloud = ground();
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    struct View {
        double yawDegrees, pitchDegrees, distance;
    };
    int holes = 0, groundPixels = 0, leaks = 0, backgroundPixels = 0;
    for (const View view : {View{10.0, 35.0, 10.0}, View{10.0, 25.0, 10.0}, View{75.0, 20.0, 8.0},
                            View{40.0, 30.0, 15.0}}) {
        const double yaw = view.yawDegrees * std::numbers::pi / 180.0;
        const double pitch = view.pitchDegrees * std::numbers::pi / 180.0;
        const glm::dvec3 eye =
            view.distance * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch),
                                       std::cos(pitch) * std::cos(yaw));
        Camera camera;
        camera.width = 320;
        camera.height = 240;
        camera.view = glm::lookAt(eye, glm::dvec3(0.0), glm::dvec3(0.0, 1.0, 0.0));
        renderer.render(camera, settings);
        const std::vector<float> depth = renderer.resources().texture("surfaceDepth").readFloats();
        ASSERT_EQ(depth.size(), static_cast<std::size_t>(camera.width * camera.height));
        const glm::dmat4 toWorld = glm::inverse(camera.view);
        for (int y = 0; y < camera.height; ++y) {
            for (int x = 0; x < camera.width; ++x) {
                const glm::dvec3 ray =
                    glm::dvec3(toWorld * glm::dvec4(pixelCentreDirection(camera, x, y), 0.0));
                // Where the ray meets the ground's plane (infinitely far for rays above it).
                const glm::dvec3 hit = ray.y < 0.0 ? eye - (eye.y / ray.y) * ray : glm::dvec3(kInf);
                const double fromCentre = std::max(std::abs(hit.x), std::abs(hit.z));
                const bool surface = std::isfinite(depth[y * camera.width + x]);
                // The ground's true edge lies within half a spacing and the jitter of its
                // outermost points; far away a pixel spans several spacings. Two metres (a few
                // pixels at that distance) inside it is surely ground, as far outside surely not.
                if (fromCentre < kGroundHalfSize - 2.0) {
                    ++groundPixels;
                    holes += !surface;
                } else if (fromCentre > kGroundHalfSize + 2.0) {
                    ++backgroundPixels;
                    leaks += surface;
                }
            }
        }
    }
    std::printf("hole pixels: %d of %d on the ground; surface on %d of %d background pixels\n",
                holes, groundPixels, leaks, backgroundPixels);
    EXPECT_GT(groundPixels, 4 * 320 * 240 / 2);
    EXPECT_GT(backgroundPixels, 4 * 320 * 240 / 20);
    // Measured 2026-12-06: 54 before the rule, 4 with it: one level-1 texel in the bottom two
    // rows, whose leftward cone lies half beyond the image (counting such cones' border too
    // closed it but let a close-up of the bunny leak more: docs/pipeline.md). Two texels'
    // worth leaves room for float rounding on other GPUs.
    EXPECT_LE(holes, 8);
    EXPECT_EQ(leaks, 0);
}

}  // namespace
}  // namespace subscan
