#pragma once

#include "core/Camera.h"

namespace subscan {

/// Where the benchmark's camera is at one moment of its path, relative to the auto-framed view.
struct PathPose {
    double yawDegrees = 0.0;
    double pitchDegrees = 0.0;
    double distanceFactor = 1.0;  // times the auto-framed distance
    double panRight = 0.0;        // orbit centre moved along the view's right axis (x radius)
    double panUp = 0.0;           // and along its up axis (x radius)
};

/// The benchmark's deterministic replay of a person looking at a scan, at `t` in [0, 1]: a slow
/// orbit, a zoom into a close-up (large gaps between points), a fast orbit there, pans, a zoom
/// out to a far view (many points per pixel), and a pitch sweep. Continuous in t.
PathPose benchmarkPose(double t);

/// The camera of `pose` around `bounds`.
Camera cameraForPose(const Bounds& bounds, const PathPose& pose, UpAxis up, int width, int height,
                     double fovyDegrees);

}  // namespace subscan
