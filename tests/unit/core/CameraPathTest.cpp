// The benchmark's camera path: continuous, and covering the situations it promises.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/CameraPath.h"

namespace subscan {
namespace {

Bounds unitBox() {
    Bounds bounds;
    bounds.min = {-1.0, -1.0, -1.0};
    bounds.max = {1.0, 1.0, 1.0};
    return bounds;
}

TEST(CameraPathTest, StartsAtTheFramedViewAndMovesSmoothly) {
    const PathPose start = benchmarkPose(0.0);
    EXPECT_DOUBLE_EQ(start.distanceFactor, 1.0);
    EXPECT_DOUBLE_EQ(start.panRight, 0.0);
    constexpr int kFrames = 600;
    for (int frame = 1; frame < kFrames; ++frame) {
        const PathPose a = benchmarkPose(double(frame - 1) / (kFrames - 1));
        const PathPose b = benchmarkPose(double(frame) / (kFrames - 1));
        // At 600 frames no step is a jump: the fastest orbit (180 degrees over 90 frames,
        // eased: at most 1.5x the mean speed) turns under 4 degrees a frame, zooms change the
        // distance under 4 % and pans (0.75 radius over 30 frames, eased) move the centre
        // under 5 % of the radius.
        EXPECT_LT(std::abs(b.yawDegrees - a.yawDegrees), 4.0) << frame;
        EXPECT_LT(std::abs(b.pitchDegrees - a.pitchDegrees), 4.0) << frame;
        EXPECT_LT(std::abs(std::log(b.distanceFactor / a.distanceFactor)), 0.04) << frame;
        EXPECT_LT(std::abs(b.panRight - a.panRight) + std::abs(b.panUp - a.panUp), 0.05) << frame;
    }
}

TEST(CameraPathTest, CoversCloseUpsFarViewsPansAndPitches) {
    double nearest = 1e9, farthest = 0.0, maxPan = 0.0, minPitch = 90.0, maxPitch = -90.0;
    double yawTravel = 0.0;
    double previousYaw = benchmarkPose(0.0).yawDegrees;
    for (int i = 0; i <= 1000; ++i) {
        const PathPose pose = benchmarkPose(i / 1000.0);
        nearest = std::min(nearest, pose.distanceFactor);
        farthest = std::max(farthest, pose.distanceFactor);
        maxPan = std::max(maxPan, std::hypot(pose.panRight, pose.panUp));
        minPitch = std::min(minPitch, pose.pitchDegrees);
        maxPitch = std::max(maxPitch, pose.pitchDegrees);
        yawTravel += std::abs(pose.yawDegrees - previousYaw);
        previousYaw = pose.yawDegrees;
    }
    EXPECT_LE(nearest, 0.3);   // a close-up: points leave gaps
    EXPECT_GE(farthest, 2.0);  // a far view: many points per pixel
    EXPECT_GE(maxPan, 0.3);
    EXPECT_LE(minPitch, -20.0);
    EXPECT_GE(maxPitch, 50.0);
    EXPECT_GE(yawTravel, 360.0);  // at least one full turn around the scan
}

TEST(CameraPathTest, PoseCamerasZoomAndPanAroundTheBounds) {
    const Bounds bounds = unitBox();
    const Camera framed = orbitCamera(bounds, OrbitView{0.0, 15.0}, 320, 240, 45.0);
    const Camera start = cameraForPose(bounds, benchmarkPose(0.0), UpAxis::Y, 320, 240, 45.0);
    EXPECT_NEAR(glm::length(start.eye() - framed.eye()), 0.0, 1e-9);  // same as auto-framed

    PathPose close;
    close.distanceFactor = 0.25;
    const Camera zoomed = cameraForPose(bounds, close, UpAxis::Y, 320, 240, 45.0);
    EXPECT_NEAR(glm::length(zoomed.eye()), 0.25 * glm::length(framed.eye()), 1e-9);
    EXPECT_GT(zoomed.nearPlane, 0.0);  // the eye is inside the bounding sphere
    EXPECT_GE(zoomed.farPlane, glm::length(zoomed.eye()) + std::sqrt(3.0));

    PathPose panned;
    panned.pitchDegrees = 15.0;  // the framed view's
    panned.panRight = 0.5;
    const Camera moved = cameraForPose(bounds, panned, UpAxis::Y, 320, 240, 45.0);
    // Panning moves eye and centre together along the view's right axis, by 0.5 radius.
    const glm::dvec3 right(framed.view[0][0], framed.view[1][0], framed.view[2][0]);
    EXPECT_NEAR(glm::dot(moved.eye() - framed.eye(), right), 0.5 * std::sqrt(3.0), 1e-9);
    EXPECT_NEAR(glm::length(moved.eye() - framed.eye()), 0.5 * std::sqrt(3.0), 1e-9);
}

}  // namespace
}  // namespace subscan
