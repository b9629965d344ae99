#include <cmath>
#include <random>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/Camera.h"
#include "core/Error.h"

namespace subscan {
namespace {

Bounds box(glm::dvec3 min, glm::dvec3 max) {
    Bounds bounds;
    bounds.add(min);
    bounds.add(max);
    return bounds;
}

TEST(CameraTest, JitterShiftsEveryPointByItsPixelsRightAndDown) {
    // The temporal filter's jitter moves the picture by (x right, y down) pixels at every
    // depth; the shaders' viewPositionAt() subtracts it (mutate-temporal.sh checks that side).
    Camera camera;
    camera.width = 64;
    camera.height = 48;
    camera.view = glm::lookAt(glm::dvec3(1, 2, 5), glm::dvec3(0), glm::dvec3(0, 1, 0));
    Camera jittered = camera;
    jittered.jitterPixels = {0.3, -0.2};
    auto window = [](const Camera& c, glm::dvec3 point) {
        const glm::dvec4 clip = c.projection() * c.view * glm::dvec4(point, 1.0);
        return glm::dvec2((clip.x / clip.w + 1.0) * 0.5 * c.width,
                          (1.0 - clip.y / clip.w) * 0.5 * c.height);
    };
    for (const glm::dvec3 point :
         {glm::dvec3(0.0), glm::dvec3(0.5, -0.3, 1.0), glm::dvec3(-1.0, 0.4, -2.0)}) {
        const glm::dvec2 shift = window(jittered, point) - window(camera, point);
        EXPECT_NEAR(shift.x, 0.3, 1e-9);  // double rounding of the projection
        EXPECT_NEAR(shift.y, -0.2, 1e-9);
    }
    EXPECT_EQ(jittered.focalLengthPixels(), camera.focalLengthPixels());
}

TEST(CameraTest, AutoFramingKeepsEveryCornerInsideTheImageAndDepthRange) {
    const Bounds bounds = box({500000, 5400000, 10}, {500040, 5400010, 25});
    for (const double yaw : {0.0, 45.0, 200.0}) {
        for (const double pitch : {-60.0, 0.0, 35.0, 90.0}) {
            for (const UpAxis up : {UpAxis::Y, UpAxis::Z}) {
                const Camera camera =
                    orbitCamera(bounds, {yaw, pitch, std::nullopt, up}, 160, 90, 45);
                for (int corner = 0; corner < 8; ++corner) {
                    const glm::dvec3 p = bounds.corner(corner);
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

TEST(CameraTest, BoxFramingFillsTheLimitingSideFromEveryDirection) {
    // A cube, a 4:1:1 bar, a flat slab and far UTM-like bounds, from around the sphere, into
    // wide, tall and square pictures, through narrow and wide fields of view: every corner
    // inside the image and the depth range, the corners' projection 95 % of the image on the
    // side that limits it, and centred on both. Wide fields used to leave it off centre (the
    // target moved by the projection's offset, which near corners dominate): at 90 degrees
    // the bunny's box spanned -0.96..0.75 of the height, at 150 one corner of the picture.
    const Bounds shapes[] = {box({0, 0, 0}, {1, 1, 1}), box({-2, 0, 0}, {2, 1, 1}),
                             box({0, 0, 0}, {3, 0.05, 2}),
                             box({500000, 5400000, 10}, {500040, 5400010, 25})};
    for (const Bounds& bounds : shapes) {
        for (const auto& [width, height] : {std::pair{160, 90}, {90, 160}, {100, 100}}) {
            for (double yaw = 0.0; yaw < 360.0; yaw += 30.0) {
                for (const double pitch : {-89.0, -45.0, 0.0, 20.0, 60.0, 90.0}) {
                    for (const UpAxis up : {UpAxis::Y, UpAxis::Z}) {
                        for (const double fovy : {10.0, 45.0, 90.0, 150.0}) {
                            OrbitView orbit{yaw, pitch, std::nullopt, up};
                            orbit.framing = Framing::Box;
                            const Camera camera = orbitCamera(bounds, orbit, width, height, fovy);
                            glm::dvec2 low(1e9), high(-1e9);
                            double nearest = 1e300;
                            for (int corner = 0; corner < 8; ++corner) {
                                const glm::dvec4 view =
                                    camera.view * glm::dvec4(bounds.corner(corner), 1.0);
                                const glm::dvec4 clip = camera.projection() * view;
                                const glm::dvec2 ndc(clip.x / clip.w, clip.y / clip.w);
                                ASSERT_GT(-view.z, camera.nearPlane);
                                ASSERT_LT(-view.z, camera.farPlane);
                                low = glm::min(low, ndc);
                                high = glm::max(high, ndc);
                                nearest = std::min(nearest, -view.z);
                            }
                            const std::string where = fmt::format("yaw {} pitch {} fovy {} {}x{}",
                                                                  yaw, pitch, fovy, width, height);
                            // Double rounding of far UTM-like bounds: well below a pixel.
                            constexpr double kTolerance = 1e-6;
                            const double filled = std::max(high.x - low.x, high.y - low.y) / 2.0;
                            // Through a wide field the eye may come to its closest, a hundredth
                            // of the bounds' radius before the nearest corner, with the corners
                            // still inside 95 %: nearer would put a corner behind it.
                            const double radius = 0.5 * glm::length(bounds.extent());
                            const bool closest = nearest < 0.0100001 * radius;
                            EXPECT_LE(filled, 0.95 + kTolerance) << where;
                            EXPECT_TRUE(closest || std::abs(filled - 0.95) < kTolerance)
                                << where << ": " << filled;
                            EXPECT_TRUE(fovy >= 90.0 || !closest) << where;
                            EXPECT_NEAR(low.x + high.x, 0.0, kTolerance) << where;
                            EXPECT_NEAR(low.y + high.y, 0.0, kTolerance) << where;
                        }
                    }
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

TEST(CameraTest, NegativeYUpLooksFromTheDepthCamerasSideUpright) {
    // A depth camera's frame: x right, y down, z forward. Yaw 0 looks from -Z, the side the
    // camera stood on, with -Y up and +X right in the picture, as the camera saw it.
    const Bounds bounds = box({-1, -1, 1}, {1, 1, 3});
    const Camera front = orbitCamera(bounds, {0, 0, 10.0, UpAxis::NegativeY}, 100, 100, 40);
    const glm::dvec3 eye = front.eye();
    EXPECT_NEAR(eye.x, 0, 1e-12);  // double-precision lookAt, as above
    EXPECT_NEAR(eye.y, 0, 1e-12);
    EXPECT_NEAR(eye.z, 2 - 10, 1e-12);
    EXPECT_GT((front.view * glm::dvec4(0, -1, 0, 0)).y, 0.99);  // -Y up in the picture
    EXPECT_GT((front.view * glm::dvec4(1, 0, 0, 0)).x, 0.99);   // +X right
    // Pitch raises the eye towards -Y; yaw turns it towards +X, as for the other axes.
    const Camera turned = orbitCamera(bounds, {90, 0, 10.0, UpAxis::NegativeY}, 100, 100, 40);
    EXPECT_NEAR(turned.eye().x, 10, 1e-9);
    const Camera raised = orbitCamera(bounds, {0, 90, 10.0, UpAxis::NegativeY}, 100, 100, 40);
    EXPECT_NEAR(raised.eye().y, -10, 1e-9);
}

TEST(CameraTest, OrbitsAboutYAndZKeepTheirDirections) {
    // The directions from the centre towards the eye, written out for Y and Z up as they were
    // before the orbit's frames were shared with -Y: every picture of those scans unchanged.
    const Bounds bounds = box({-1, -1, -1}, {1, 1, 1});
    const double yaw = glm::radians(-70.0), pitch = glm::radians(35.0);
    const glm::dvec3 yUp(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                         std::cos(yaw) * std::cos(pitch));
    const glm::dvec3 zUp(std::sin(yaw) * std::cos(pitch), -std::cos(yaw) * std::cos(pitch),
                         std::sin(pitch));
    for (const auto& [up, direction] : {std::pair{UpAxis::Y, yUp}, std::pair{UpAxis::Z, zUp}}) {
        const Camera camera = orbitCamera(bounds, {-70, 35, 4.0, up}, 100, 100, 40);
        // Double-precision lookAt, as above.
        EXPECT_LT(glm::length(camera.eye() - 4.0 * direction), 1e-12) << int(up);
    }
}

TEST(CameraTest, ViewsAlongTheUpAxisStillTurnWithTheYaw) {
    // Straight down (or up) the picture's up has no horizon to follow; it must be the limit the
    // view takes as the pitch nears ±90°, so the picture turns with the yaw and does not jump
    // where the up vector is replaced (an outside test found yaw ignored from pitch 89.2° on).
    const Bounds bounds = box({-1, -1, -1}, {1, 1, 1});
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        for (const double pitch : {90.0, -90.0}) {
            for (const double yaw : {0.0, 30.0, 90.0, -135.0}) {
                const Camera pole = orbitCamera(bounds, {yaw, pitch, 5.0, up}, 100, 100, 40);
                const Camera near = orbitCamera(
                    bounds, {yaw, pitch - std::copysign(0.5, pitch), 5.0, up}, 100, 100, 40);
                // The picture's right axis (the view's first row) in world space: horizontal
                // at every pitch, so the same half a degree from the pole (to double rounding);
                // the jump there was one of 90°, a difference of 1.4.
                const glm::dvec3 right(pole.view[0][0], pole.view[1][0], pole.view[2][0]);
                const glm::dvec3 nearRight(near.view[0][0], near.view[1][0], near.view[2][0]);
                EXPECT_LT(glm::length(right - nearRight), 1e-9)
                    << int(up) << " pitch " << pitch << " yaw " << yaw;
            }
            // Turning the yaw by 90° at the pole turns the picture's right axis by 90°.
            const Camera a = orbitCamera(bounds, {0, pitch, 5.0, up}, 100, 100, 40);
            const Camera b = orbitCamera(bounds, {90, pitch, 5.0, up}, 100, 100, 40);
            const double cosine = a.view[0][0] * b.view[0][0] + a.view[1][0] * b.view[1][0] +
                                  a.view[2][0] * b.view[2][0];
            EXPECT_NEAR(cosine, 0.0, 1e-9) << int(up);  // double-precision lookAt
        }
    }
}

TEST(CameraTest, OrbitAnglesInvertTheOrbitForEveryUpAxis) {
    const Bounds bounds = box({-1, -1, -1}, {1, 1, 1});
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        for (const glm::dvec2 angles : {glm::dvec2(30, 20), glm::dvec2(-135, -50)}) {
            const Camera camera = orbitCamera(bounds, {angles.x, angles.y, 5.0, up}, 100, 100, 40);
            const glm::dvec2 back = orbitAngles(camera.eye() - bounds.center(), up);
            // Angles from double-precision vectors: far below a thousandth of a degree.
            EXPECT_NEAR(back.x, angles.x, 1e-9) << int(up);
            EXPECT_NEAR(back.y, angles.y, 1e-9) << int(up);
        }
    }
    EXPECT_EQ(upAxisFor("-y", "pcd"), UpAxis::NegativeY);
    EXPECT_THROW(upAxisFor("-z", "pcd"), Error);
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

/// The pixel a rasterizer puts `p` in (floor of its window position), or nothing when it does
/// not project into the image in front of the near plane.
std::optional<glm::ivec2> pixelOf(const Camera& camera, const glm::dvec3& p) {
    const glm::dvec4 view = camera.view * glm::dvec4(p, 1.0);
    if (-view.z <= camera.nearPlane) {
        return std::nullopt;
    }
    const glm::dvec4 clip = camera.projection() * view;
    const glm::ivec2 pixel(
        static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * camera.width)),
        static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * camera.height)));
    if (pixel.x < 0 || pixel.y < 0 || pixel.x >= camera.width || pixel.y >= camera.height) {
        return std::nullopt;
    }
    return pixel;
}

TEST(CameraTest, ProjectedPixelBoundsHoldEveryPointOfTheBoxAndLittleElse) {
    const Bounds bounds = box({-1, -0.5, -0.25}, {1, 0.5, 0.25});
    std::mt19937 random(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int views = 0;
    for (const double distance : {1.2, 3.0, 12.0}) {
        for (const double yaw : {0.0, 35.0, 130.0}) {
            const Camera camera =
                orbitCamera(bounds, {yaw, 20.0, distance, UpAxis::Y}, 161, 97, 45);
            const glm::ivec4 rect = projectedPixelBounds(camera, bounds);
            glm::ivec2 low(camera.width, camera.height);
            glm::ivec2 high(-1);
            for (int i = 0; i < 4000; ++i) {
                const glm::dvec3 p =
                    bounds.min +
                    bounds.extent() * glm::dvec3(unit(random), unit(random), unit(random));
                if (const auto pixel = pixelOf(camera, p)) {
                    EXPECT_TRUE(pixel->x >= rect.x && pixel->y >= rect.y && pixel->x < rect.z &&
                                pixel->y < rect.w)
                        << "distance " << distance << " yaw " << yaw;
                    low = glm::min(low, *pixel);
                    high = glm::max(high, *pixel);
                }
            }
            if (rect != glm::ivec4(0, 0, camera.width, camera.height)) {
                ++views;
                // Tight: the random points reach within a few pixels of the box's outline,
                // plus the 2-pixel margin on each side.
                EXPECT_LE(low.x - rect.x, 6);
                EXPECT_LE(rect.z - 1 - high.x, 6);
                EXPECT_LE(low.y - rect.y, 6);
                EXPECT_LE(rect.w - 1 - high.y, 6);
            }
        }
    }
    EXPECT_GE(views, 3);  // the far views do not cover the image
}

TEST(CameraTest, ProjectedPixelBoundsAreTheWholeImageWhenTheBoxReachesBehindTheCamera) {
    const Bounds bounds = box({-1, -1, -1}, {1, 1, 1});
    Camera inside = orbitCamera(bounds, {0, 0, 0.5, UpAxis::Y}, 64, 48, 45);
    EXPECT_EQ(projectedPixelBounds(inside, bounds), glm::ivec4(0, 0, 64, 48));
    EXPECT_EQ(projectedPixelBounds(inside, Bounds{}), glm::ivec4(0));
    // A box entirely beside the view projects nowhere into the image.
    const Camera framed = orbitCamera(bounds, {0, 0, 10.0, UpAxis::Y}, 64, 48, 45);
    const glm::ivec4 aside = projectedPixelBounds(framed, box({30, -1, -1}, {32, 1, 1}));
    EXPECT_LE(aside.z, aside.x);
}

TEST(CameraTest, OrthographicCameraMapsSceneUnitsToPixelsAtEveryDepth) {
    Camera camera;
    camera.width = 200;
    camera.height = 100;
    camera.orthographicHeight = 4.0;  // 25 pixels per unit
    camera.nearPlane = 1.0;
    camera.farPlane = 9.0;
    ASSERT_TRUE(camera.orthographic());
    EXPECT_DOUBLE_EQ(camera.focalLengthPixels(), 25.0);
    for (const double depth : {1.5, 4.0, 8.5}) {
        // 2 units right of and 1 unit above the axis: 50 and 25 pixels from the middle.
        const glm::dvec4 clip = camera.projection() * glm::dvec4(2.0, 1.0, -depth, 1.0);
        EXPECT_DOUBLE_EQ(clip.w, 1.0);
        EXPECT_NEAR((clip.x + 1.0) * 0.5 * camera.width, 150.0, 1e-9);
        EXPECT_NEAR((1.0 - clip.y) * 0.5 * camera.height, 25.0, 1e-9);
    }
    // The projected box: x 100 + 25 * [-1, 1], y 50 - 25 * [-1, 1], plus the 2-pixel margin.
    EXPECT_EQ(projectedPixelBounds(camera, box({-1, -1, -5}, {1, 1, -3})),
              glm::ivec4(73, 23, 128, 78));
}

}  // namespace
}  // namespace subscan
