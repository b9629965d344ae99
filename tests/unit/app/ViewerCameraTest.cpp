#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "app/viewer/ViewerCamera.h"

namespace subscan::viewer {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 200;
// Double-precision maths on scenes of size ~10: anything above 1e-9 would be a real error.
constexpr double kTolerance = 1e-9;
// Where a point lands in the 320 x 200 image after the same maths: measured at most 2.8e-14
// pixels (2026-12-03), an ulp or so of a coordinate below 320. 1e-10 leaves three orders of
// magnitude for a longer chain of operations and fails any real offset.
constexpr double kPixelTolerance = 1e-10;

Bounds box(glm::dvec3 min, glm::dvec3 max) {
    Bounds bounds;
    bounds.add(min);
    bounds.add(max);
    return bounds;
}

const Bounds kScene = box({-2, 1, 3}, {4, 5, 6});

void expectNear(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance) {
    EXPECT_NEAR(actual.x, expected.x, tolerance);
    EXPECT_NEAR(actual.y, expected.y, tolerance);
    EXPECT_NEAR(actual.z, expected.z, tolerance);
}

/// Window pixel (from the top left) and linear depth of a scene point, by the pixel convention
/// of docs/cli.md: x = (ndc.x + 1) / 2 * W, y = (1 - ndc.y) / 2 * H.
struct Projected {
    glm::dvec2 pixel;
    double depth;
};
Projected project(const Camera& camera, const glm::dvec3& point) {
    const glm::dvec4 view = camera.view * glm::dvec4(point, 1.0);
    const glm::dvec4 clip = camera.projection() * view;
    const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
    return {{(ndc.x + 1.0) * 0.5 * camera.width, (1.0 - ndc.y) * 0.5 * camera.height}, -view.z};
}

/// A camera somewhere else than the default: orbited, panned and zoomed.
ViewerCamera movedCamera(UpAxis up) {
    ViewerCamera camera(kScene, up, kWidth, kHeight);
    camera.orbit(140.0, -60.0);
    camera.pan(25.0, 10.0, kHeight);
    camera.zoomTowards(1.5, camera.pointAtCentreDepth({200.0, 80.0}, kWidth, kHeight));
    return camera;
}

TEST(ViewerCameraTest, ResetIsTheAutoFramedViewOfOrbitCamera) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        camera.reset(kWidth, kHeight);
        OrbitView orbit{30.0, 20.0, std::nullopt, up};
        orbit.framing = Framing::Box;
        const Camera expected =
            orbitCamera(kScene, orbit, kWidth, kHeight, ViewerCamera::kFovyDegrees);
        const Camera actual = camera.camera(kWidth, kHeight);
        for (int column = 0; column < 4; ++column) {
            for (int row = 0; row < 4; ++row) {
                EXPECT_NEAR(actual.view[column][row], expected.view[column][row], kTolerance);
            }
        }
        EXPECT_NEAR(actual.nearPlane, expected.nearPlane, kTolerance);
        EXPECT_NEAR(actual.farPlane, expected.farPlane, kTolerance);
        EXPECT_EQ(actual.width, kWidth);
        EXPECT_EQ(actual.height, kHeight);
    }
}

TEST(ViewerCameraTest, OrbitKeepsTheCentreAndTheDistanceToIt) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        const glm::dvec3 centre = camera.centre();
        const glm::dvec3 eyeBefore = camera.eye();
        const double distance = glm::length(eyeBefore - centre);
        for (const glm::dvec2 drag : {glm::dvec2(100, 0), glm::dvec2(0, 50), glm::dvec2(-30, 20)}) {
            camera.orbit(drag.x, drag.y);
            expectNear(camera.centre(), centre, kTolerance);
            EXPECT_NEAR(glm::length(camera.eye() - centre), distance, kTolerance);
            // The centre stays in the middle of the image.
            const Projected projected = project(camera.camera(kWidth, kHeight), centre);
            EXPECT_NEAR(projected.pixel.x, kWidth / 2.0, kPixelTolerance);
            EXPECT_NEAR(projected.pixel.y, kHeight / 2.0, kPixelTolerance);
        }
        EXPECT_GT(glm::length(camera.eye() - eyeBefore), 0.1 * distance);
    }
}

TEST(ViewerCameraTest, OrbitStopsShortOfThePoles) {
    ViewerCamera camera(kScene, UpAxis::Y, kWidth, kHeight);
    camera.orbit(0.0, 1e6);
    EXPECT_DOUBLE_EQ(camera.pitchDegrees(), ViewerCamera::kMaxPitchDegrees);
    camera.orbit(0.0, -1e6);
    EXPECT_DOUBLE_EQ(camera.pitchDegrees(), -ViewerCamera::kMaxPitchDegrees);
    const Camera view = camera.camera(kWidth, kHeight);
    for (int column = 0; column < 4; ++column) {
        for (int row = 0; row < 4; ++row) {
            EXPECT_TRUE(std::isfinite(view.view[column][row]));
        }
    }
}

TEST(ViewerCameraTest, DraggingRightTurnsTheSceneRight) {
    // Grabbing the front of the scene and dragging right moves the eye to the left of it.
    ViewerCamera camera(kScene, UpAxis::Y, kWidth, kHeight);
    const glm::dvec3 rightBefore = camera.right();
    const glm::dvec3 eyeBefore = camera.eye() - camera.centre();
    camera.orbit(30.0, 0.0);
    EXPECT_LT(glm::dot(camera.eye() - camera.centre() - eyeBefore, rightBefore), 0.0);
}

TEST(ViewerCameraTest, PanMovesCentreAndEyeTogetherWithTheCursor) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        const glm::dvec3 centreBefore = camera.centre();
        const glm::dvec3 eyeBefore = camera.eye();
        const glm::dvec3 forwardBefore = camera.forward();
        camera.pan(40.0, -25.0, kHeight);
        const glm::dvec3 centreMove = camera.centre() - centreBefore;
        expectNear(camera.eye() - eyeBefore, centreMove, kTolerance);
        EXPECT_GT(glm::length(centreMove), 0.0);
        EXPECT_NEAR(glm::dot(centreMove, forwardBefore), 0.0, kTolerance);
        // The scene point that was at the centre followed the drag.
        const Projected projected = project(camera.camera(kWidth, kHeight), centreBefore);
        EXPECT_NEAR(projected.pixel.x, kWidth / 2.0 + 40.0, kPixelTolerance);
        EXPECT_NEAR(projected.pixel.y, kHeight / 2.0 - 25.0, kPixelTolerance);
    }
}

TEST(ViewerCameraTest, ZoomMovesTowardsThePointUnderTheCursorAndKeepsItThere) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        const Camera before = camera.camera(kWidth, kHeight);
        const glm::dvec2 cursor(250.5, 40.5);
        // A surface point under the cursor, as the viewer reads it back from the depth buffer.
        const glm::dvec3 target = ViewerCamera::unproject(before, cursor, 0.8 * camera.distance());
        const glm::dvec3 forward = camera.forward();
        const double distanceBefore = glm::length(camera.eye() - target);

        camera.zoomTowards(2.0, target);
        const double closer = glm::length(camera.eye() - target);
        EXPECT_NEAR(closer,
                    distanceBefore * ViewerCamera::kZoomPerStep * ViewerCamera::kZoomPerStep,
                    kTolerance);
        expectNear(camera.forward(), forward, kTolerance);
        const Projected projected = project(camera.camera(kWidth, kHeight), target);
        EXPECT_NEAR(projected.pixel.x, cursor.x, kPixelTolerance);
        EXPECT_NEAR(projected.pixel.y, cursor.y, kPixelTolerance);

        camera.zoomTowards(-3.0, target);
        EXPECT_GT(glm::length(camera.eye() - target), distanceBefore);
    }
}

TEST(ViewerCameraTest, ZoomStopsBeforeReachingTheTarget) {
    ViewerCamera camera(kScene, UpAxis::Y, kWidth, kHeight);
    const glm::dvec3 target = camera.centre();
    camera.zoomTowards(1e4, target);
    EXPECT_GT(glm::length(camera.eye() - target), 0.0);
    EXPECT_GT(camera.distance(), 0.0);
}

TEST(ViewerCameraTest, FrameAllContainsTheBoundsFromAnyDirectionAndAspect) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        for (const glm::ivec2 size :
             {glm::ivec2(320, 200), glm::ivec2(200, 320), glm::ivec2(64, 64)}) {
            ViewerCamera camera = movedCamera(up);
            camera.orbit(77.0, 33.0);
            camera.frameAll(size.x, size.y);
            const Camera view = camera.camera(size.x, size.y);
            for (int corner = 0; corner < 8; ++corner) {
                const glm::dvec3 p = kScene.corner(corner);
                const Projected projected = project(view, p);
                EXPECT_GE(projected.pixel.x, 0.0);
                EXPECT_LE(projected.pixel.x, size.x);
                EXPECT_GE(projected.pixel.y, 0.0);
                EXPECT_LE(projected.pixel.y, size.y);
                EXPECT_GT(projected.depth, view.nearPlane);
                EXPECT_LT(projected.depth, view.farPlane);
            }
        }
    }
}

TEST(ViewerCameraTest, SetCentreKeepsTheEyeAndTurnsTowardsThePoint) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        const glm::dvec3 eye = camera.eye();
        const glm::dvec3 point = ViewerCamera::unproject(camera.camera(kWidth, kHeight),
                                                         {60.0, 150.0}, 0.7 * camera.distance());
        camera.setCentre(point);
        expectNear(camera.eye(), eye, 1e-9);
        expectNear(camera.centre(), point, kTolerance);
        EXPECT_NEAR(camera.distance(), glm::length(eye - point), kTolerance);
        const Projected projected = project(camera.camera(kWidth, kHeight), point);
        EXPECT_NEAR(projected.pixel.x, kWidth / 2.0, kPixelTolerance);
        EXPECT_NEAR(projected.pixel.y, kHeight / 2.0, kPixelTolerance);
    }
}

TEST(ViewerCameraTest, LookFromPutsTheEyeThereAndTheTargetInTheMiddle) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        ViewerCamera camera = movedCamera(up);
        const glm::dvec3 eye(0.3, -0.2, 0.4);
        const glm::dvec3 target(-0.1, 0.05, -0.2);
        camera.lookFrom(eye, target);
        expectNear(camera.eye(), eye, kTolerance);
        expectNear(camera.centre(), target, kTolerance);
        const Projected projected = project(camera.camera(kWidth, kHeight), target);
        EXPECT_NEAR(projected.pixel.x, kWidth / 2.0, kPixelTolerance);
        EXPECT_NEAR(projected.pixel.y, kHeight / 2.0, kPixelTolerance);
    }
}

TEST(ViewerCameraTest, FlyLookTurnsAroundTheEyeAndMoveShiftsBoth) {
    ViewerCamera camera = movedCamera(UpAxis::Y);
    const glm::dvec3 eye = camera.eye();
    const glm::dvec3 forward = camera.forward();
    camera.look(50.0, -20.0);
    expectNear(camera.eye(), eye, kTolerance);
    EXPECT_LT(glm::dot(camera.forward(), forward), 0.99);
    // Dragging right looks right.
    EXPECT_GT(glm::dot(camera.forward() - forward, glm::cross(forward, glm::dvec3(0, 1, 0))), 0.0);

    const glm::dvec3 centre = camera.centre();
    const glm::dvec3 right = camera.right();
    const glm::dvec3 backward = -camera.forward();
    camera.move({0.5, 0.0, -2.0});
    expectNear(camera.eye() - eye, 0.5 * right - 2.0 * backward, kTolerance);
    expectNear(camera.centre() - centre, 0.5 * right - 2.0 * backward, kTolerance);
}

TEST(ViewerCameraTest, UnprojectInvertsTheReadmePixelConvention) {
    const ViewerCamera viewer = movedCamera(UpAxis::Z);
    const Camera camera = viewer.camera(kWidth, kHeight);
    const glm::dvec3 point = kScene.center() + glm::dvec3(0.3, -0.2, 0.4);
    const Projected projected = project(camera, point);
    expectNear(ViewerCamera::unproject(camera, projected.pixel, projected.depth), point, 1e-9);
}

TEST(ViewerCameraTest, PointAtCentreDepthLiesOnTheCursorRay) {
    const ViewerCamera viewer = movedCamera(UpAxis::Y);
    const Camera camera = viewer.camera(kWidth, kHeight);
    const glm::dvec2 cursor(17.0, 181.0);
    const glm::dvec3 point = viewer.pointAtCentreDepth(cursor, kWidth, kHeight);
    const Projected projected = project(camera, point);
    EXPECT_NEAR(projected.pixel.x, cursor.x, kPixelTolerance);
    EXPECT_NEAR(projected.pixel.y, cursor.y, kPixelTolerance);
    EXPECT_NEAR(projected.depth, viewer.distance(), kTolerance);
}

/// A direction in the frame of `camera`'s view: x right, y up, z towards the eye.
glm::dvec3 inView(const ViewerCamera& camera, const glm::dvec3& view) {
    return view.x * camera.right() + view.y * camera.up() - view.z * camera.forward();
}

TEST(ViewerCameraTest, DraggingTheLightTurnsItAroundTheViewsUpAndRightAxes) {
    // 0.3 degrees a pixel: 300 pixels are a quarter turn, 150 an eighth.
    const double eighth = 45.0 / ViewerCamera::kDegreesPerPixel;
    const double quarter = 2.0 * eighth;
    const double s = std::sqrt(0.5);
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        const ViewerCamera camera = movedCamera(up);
        const glm::dvec3 front = inView(camera, {0, 0, 1});  // from the eye's side
        // Right moves a front light to the right, left to the left; up raises it, down lowers.
        expectNear(camera.dragLight(front, quarter, 0.0), camera.right(), 1e-12);
        expectNear(camera.dragLight(front, -quarter, 0.0), -camera.right(), 1e-12);
        expectNear(camera.dragLight(front, eighth, 0.0), inView(camera, {s, 0, s}), 1e-12);
        expectNear(camera.dragLight(front, 0.0, -eighth), inView(camera, {0, s, s}), 1e-12);
        expectNear(camera.dragLight(front, 0.0, eighth), inView(camera, {0, -s, s}), 1e-12);
        // Half a turn puts it behind the scene, against the eye.
        expectNear(camera.dragLight(front, 2.0 * quarter, 0.0), camera.forward(), 1e-12);
        // A light from the right, raised by an eighth, then carried a quarter to the right.
        expectNear(camera.dragLight(camera.right(), quarter, -eighth), inView(camera, {0, s, -s}),
                   1e-12);
        // The length of the given direction does not matter; the result is a unit vector.
        expectNear(camera.dragLight(7.0 * front, eighth, 0.0), inView(camera, {s, 0, s}), 1e-12);
        expectNear(camera.dragLight(front, 0.0, 0.0), front, 1e-12);
    }
}

TEST(ViewerCameraTest, DraggingTheLightKeepsElevationAcrossAndStopsShortOfThePoles) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        const ViewerCamera camera = movedCamera(up);
        const glm::dvec3 light = glm::normalize(inView(camera, {-0.3, 0.5, 0.8}));
        // Across: the height above the view's horizon stays; back again: where it was.
        const glm::dvec3 across = camera.dragLight(light, 237.0, 0.0);
        EXPECT_NEAR(glm::dot(across, camera.up()), glm::dot(light, camera.up()), 1e-12);
        EXPECT_NEAR(glm::length(across), 1.0, 1e-12);
        expectNear(camera.dragLight(camera.dragLight(light, 80.0, -45.0), -80.0, 45.0), light,
                   1e-12);
        // Far up or down, the light stops kMaxPitchDegrees from the view's up axis, where a
        // further drag across still turns it.
        const double maxElevation = glm::radians(ViewerCamera::kMaxPitchDegrees);
        for (const double sign : {1.0, -1.0}) {
            const glm::dvec3 pole = camera.dragLight(light, 0.0, -sign * 1e5);
            EXPECT_NEAR(glm::dot(pole, camera.up()), sign * std::sin(maxElevation), 1e-12);
            const glm::dvec3 turned = camera.dragLight(pole, 300.0, 0.0);
            EXPECT_NEAR(glm::dot(turned, camera.up()), sign * std::sin(maxElevation), 1e-12);
            EXPECT_LT(glm::dot(turned, pole), 0.9999);
        }
        // A zero direction (no light to turn) starts from the eye's side.
        expectNear(camera.dragLight(glm::dvec3(0.0), 0.0, 0.0), inView(camera, {0, 0, 1}), 1e-12);
    }
}

TEST(ViewerCameraTest, TheDefaultLightComesFromTheUpperLeftOnTheEyesSide) {
    for (const UpAxis up : {UpAxis::Y, UpAxis::Z, UpAxis::NegativeY}) {
        const ViewerCamera camera = movedCamera(up);
        expectNear(camera.defaultLightDirection(),
                   inView(camera, glm::dvec3(-1.0, 1.0, 1.0) / std::sqrt(3.0)), 1e-12);
    }
}

}  // namespace
}  // namespace subscan::viewer
