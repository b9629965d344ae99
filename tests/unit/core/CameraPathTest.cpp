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
        // At 600 frames no step is a jump. Each motion eases (smoothstep) over its share of the
        // path: its fastest step is at most 1.5x its mean one, so at most
        // 1.5 x change / (share x 599 steps). The fastest of each kind: the orbit of 180 degrees
        // over 15 % of the path, 3.005 degrees a step; the pitch from 60 to -30 degrees over
        // 10 %, 2.254 degrees; the zoom out from 0.25 to 2.5 over 15 %, ln 10 in log distance,
        // 0.0384; the pan from (0.3, 0) to (-0.2, 0.25) radius over 5 %, 0.75 in |right| + |up|,
        // 0.0376 of the radius. (Measured: 3.0049, 2.2530, 0.038438, 0.037546.)
        const auto fastestStep = [&](double change, double share) {
            return 1.5 * change / (share * (kFrames - 1));
        };
        EXPECT_LE(std::abs(b.yawDegrees - a.yawDegrees), fastestStep(180.0, 0.15)) << frame;
        EXPECT_LE(std::abs(b.pitchDegrees - a.pitchDegrees), fastestStep(90.0, 0.10)) << frame;
        EXPECT_LE(std::abs(std::log(b.distanceFactor / a.distanceFactor)),
                  fastestStep(std::log(10.0), 0.15))
            << frame;
        EXPECT_LE(std::abs(b.panRight - a.panRight) + std::abs(b.panUp - a.panUp),
                  fastestStep(0.75, 0.05))
            << frame;
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
    // What the path must show, each with room below what its keyframes reach (measured on
    // these 1001 samples: 0.25, 2.5, 0.320, -30, 60 and 360 degrees exactly).
    EXPECT_LE(nearest, 0.3);      // a close-up: points leave gaps
    EXPECT_GE(farthest, 2.0);     // a far view: many points per pixel
    EXPECT_GE(maxPan, 0.3);       // a pan off the centre by a third of the radius
    EXPECT_LE(minPitch, -20.0);   // views from below
    EXPECT_GE(maxPitch, 50.0);    // and from well above
    EXPECT_GE(yawTravel, 360.0);  // at least one full turn around the scan
}

TEST(CameraPathTest, PoseCamerasZoomAndPanAroundTheBounds) {
    const Bounds bounds = unitBox();
    const Camera framed = orbitCamera(bounds, OrbitView{0.0, 15.0}, 320, 240, 45.0);
    const Camera start = cameraForPose(bounds, benchmarkPose(0.0), UpAxis::Y, 320, 240, 45.0);
    // Same as auto-framed. Eye positions are ~5 from the origin, where a double's ulp is 9e-16:
    // 1e-12 is a thousand ulps (measured: 0 here and in the zoom, 2.2e-16 in the pan).
    constexpr double kTolerance = 1e-12;
    EXPECT_NEAR(glm::length(start.eye() - framed.eye()), 0.0, kTolerance);

    PathPose close;
    close.distanceFactor = 0.25;
    const Camera zoomed = cameraForPose(bounds, close, UpAxis::Y, 320, 240, 45.0);
    EXPECT_NEAR(glm::length(zoomed.eye()), 0.25 * glm::length(framed.eye()), kTolerance);
    EXPECT_GT(zoomed.nearPlane, 0.0);  // the eye is inside the bounding sphere
    EXPECT_GE(zoomed.farPlane, glm::length(zoomed.eye()) + std::sqrt(3.0));

    PathPose panned;
    panned.pitchDegrees = 15.0;  // the framed view's
    panned.panRight = 0.5;
    const Camera moved = cameraForPose(bounds, panned, UpAxis::Y, 320, 240, 45.0);
    // Panning moves eye and centre together along the view's right axis, by 0.5 radius.
    const glm::dvec3 right(framed.view[0][0], framed.view[1][0], framed.view[2][0]);
    EXPECT_NEAR(glm::dot(moved.eye() - framed.eye(), right), 0.5 * std::sqrt(3.0), kTolerance);
    EXPECT_NEAR(glm::length(moved.eye() - framed.eye()), 0.5 * std::sqrt(3.0), kTolerance);
}

}  // namespace
}  // namespace subscan
