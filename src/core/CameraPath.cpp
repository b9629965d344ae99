#include "core/CameraPath.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace subscan {

namespace {

struct Keyframe {
    double t;
    PathPose pose;
};

// Orbit speeds: 90 degrees over 25 % of the path (slow), 180 degrees over 15 % (fast).
constexpr std::array<Keyframe, 9> kKeyframes{{
    {0.00, {0.0, 15.0, 1.0, 0.0, 0.0}},
    {0.25, {90.0, 15.0, 1.0, 0.0, 0.0}},      // slow orbit
    {0.40, {110.0, 10.0, 0.25, 0.0, 0.0}},    // zoom into a close-up
    {0.55, {290.0, 10.0, 0.25, 0.0, 0.0}},    // fast orbit, close
    {0.60, {290.0, 10.0, 0.25, 0.3, 0.0}},    // pan right
    {0.65, {290.0, 10.0, 0.25, -0.2, 0.25}},  // pan left and up
    {0.80, {320.0, 20.0, 2.5, 0.0, 0.0}},     // zoom out to a far view
    {0.90, {340.0, 60.0, 1.0, 0.0, 0.0}},     // pitch up
    {1.00, {360.0, -30.0, 1.0, 0.0, 0.0}},    // pitch down
}};

double mix(double a, double b, double s) {
    return a + (b - a) * s;
}

}  // namespace

PathPose benchmarkPose(double t) {
    t = std::clamp(t, 0.0, 1.0);
    const auto next = std::find_if(kKeyframes.begin() + 1, kKeyframes.end() - 1,
                                   [t](const Keyframe& key) { return t <= key.t; });
    const Keyframe& a = *(next - 1);
    const Keyframe& b = *next;
    // Smoothstep between keyframes: a person eases in and out of each motion.
    double s = (t - a.t) / (b.t - a.t);
    s = s * s * (3.0 - 2.0 * s);
    // Distances interpolate geometrically, as a zoom does.
    return {mix(a.pose.yawDegrees, b.pose.yawDegrees, s),
            mix(a.pose.pitchDegrees, b.pose.pitchDegrees, s),
            a.pose.distanceFactor * std::pow(b.pose.distanceFactor / a.pose.distanceFactor, s),
            mix(a.pose.panRight, b.pose.panRight, s), mix(a.pose.panUp, b.pose.panUp, s)};
}

Camera cameraForPose(const Bounds& bounds, const PathPose& pose, UpAxis up, int width, int height,
                     double fovyDegrees) {
    OrbitView orbit;
    orbit.yawDegrees = pose.yawDegrees;
    orbit.pitchDegrees = pose.pitchDegrees;
    orbit.up = up;
    const Camera framed = orbitCamera(bounds, orbit, width, height, fovyDegrees);
    const glm::dvec3 middle = bounds.center();
    const double autoDistance = glm::length(framed.eye() - middle);
    const double radius = 0.5 * glm::length(bounds.extent());
    // The view's right and up axes in file coordinates: the first two rows of its rotation.
    const glm::dvec3 right(framed.view[0][0], framed.view[1][0], framed.view[2][0]);
    const glm::dvec3 upAxis(framed.view[0][1], framed.view[1][1], framed.view[2][1]);
    orbit.center = middle + radius * (pose.panRight * right + pose.panUp * upAxis);
    orbit.distance = pose.distanceFactor * autoDistance;
    return orbitCamera(bounds, orbit, width, height, fovyDegrees);
}

}  // namespace subscan
