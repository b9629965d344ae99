#include "core/Camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

#include "core/Error.h"

namespace subscan {

glm::dmat4 Camera::projection() const {
    glm::dmat4 projection;
    if (orthographic()) {
        const double halfHeight = 0.5 * orthographicHeight;
        const double halfWidth = halfHeight * width / static_cast<double>(height);
        projection =
            glm::ortho(-halfWidth, halfWidth, -halfHeight, halfHeight, nearPlane, farPlane);
    } else {
        projection = glm::perspective(glm::radians(fovyDegrees),
                                      static_cast<double>(width) / static_cast<double>(height),
                                      nearPlane, farPlane);
    }
    const glm::dvec2 shiftPixels = pictureShiftPixels();
    if (shiftPixels == glm::dvec2(0.0)) {
        return projection;
    }
    // A shift in normalized device coordinates (2 / size per pixel; window y runs down): as a
    // translation of clip space it scales with w, so it moves every depth alike.
    const glm::dvec3 shift(2.0 * shiftPixels.x / width, -2.0 * shiftPixels.y / height, 0.0);
    return glm::translate(glm::dmat4(1.0), shift) * projection;
}

double Camera::focalLengthPixels() const {
    if (orthographic()) {
        return static_cast<double>(height) / orthographicHeight;
    }
    return 0.5 * static_cast<double>(height) / std::tan(0.5 * glm::radians(fovyDegrees));
}

glm::dvec3 Camera::eye() const {
    return glm::dvec3(glm::inverse(view) * glm::dvec4(0, 0, 0, 1));
}

glm::dmat4 Camera::translation(const glm::dvec3& offset) {
    return glm::translate(glm::dmat4(1.0), offset);
}

glm::ivec4 projectedPixelBounds(const Camera& camera, const Bounds& bounds) {
    const glm::ivec4 whole(0, 0, camera.width, camera.height);
    if (bounds.empty()) {
        return glm::ivec4(0);
    }
    const glm::dmat4 projection = camera.projection();
    glm::dvec2 low(std::numeric_limits<double>::infinity());
    glm::dvec2 high(-std::numeric_limits<double>::infinity());
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p = bounds.corner(corner);
        const glm::dvec4 viewPosition = camera.view * glm::dvec4(p, 1.0);
        if (!(-viewPosition.z > camera.nearPlane)) {
            return whole;
        }
        const glm::dvec4 clip = projection * viewPosition;
        const glm::dvec2 window((clip.x / clip.w + 1.0) * 0.5 * camera.width,
                                (1.0 - clip.y / clip.w) * 0.5 * camera.height);
        low = glm::min(low, window);
        high = glm::max(high, window);
    }
    // A box in front of the camera projects inside the hull of its corners' projections.
    constexpr double kMargin = 2.0;
    const glm::dvec2 size(camera.width, camera.height);
    const glm::dvec2 first = glm::clamp(glm::floor(low) - kMargin, glm::dvec2(0.0), size);
    const glm::dvec2 last = glm::clamp(glm::floor(high) + 1.0 + kMargin, glm::dvec2(0.0), size);
    return {static_cast<int>(first.x), static_cast<int>(first.y), static_cast<int>(last.x),
            static_cast<int>(last.y)};
}

namespace {

/// The least eye distance from `target` at which every corner of `bounds` lies within 95 % of
/// the half-fields (tangents `tanX`, `tanY`) of a camera turned by `rotation` (world to view):
/// a corner at (x, y, z) relative to the target in view axes is d - z deep, so it fits when
/// d >= z + |x| / (0.95 tanX) and d >= z + |y| / (0.95 tanY). At least a hundredth of `radius`
/// in front of the nearest corner, for a box that is flat towards the eye.
double boxFramingDistance(const Bounds& bounds, const glm::dvec3& target,
                          const glm::dmat3& rotation, double tanX, double tanY, double radius) {
    constexpr double kFill = 0.95;
    double distance = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 v = rotation * (bounds.corner(corner) - target);
        distance = std::max({distance, v.z + std::abs(v.x) / (kFill * tanX),
                             v.z + std::abs(v.y) / (kFill * tanY), v.z + 0.01 * radius});
    }
    return distance;
}

struct BoxFit {
    glm::dvec3 target;
    double distance;
};

/// Frames the box's corners: the distance above, with the target moved across the line of
/// sight (the view's direction kept) until their projection is centred. Perspective makes the
/// near side of a box look larger, so about the bounds' middle one side would touch the border
/// and the other stay well inside; a few steps of moving by the projection's offset centre it.
BoxFit fitBox(const Bounds& bounds, const glm::dvec3& center, const glm::dmat3& rotation,
              double tanX, double tanY, double radius) {
    BoxFit fit{center, 0.0};
    for (int step = 0; step < 4; ++step) {
        fit.distance = boxFramingDistance(bounds, fit.target, rotation, tanX, tanY, radius);
        glm::dvec2 low(std::numeric_limits<double>::infinity());
        glm::dvec2 high(-std::numeric_limits<double>::infinity());
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 v = rotation * (bounds.corner(corner) - fit.target);
            const glm::dvec2 ndc(v.x / ((fit.distance - v.z) * tanX),
                                 v.y / ((fit.distance - v.z) * tanY));
            low = glm::min(low, ndc);
            high = glm::max(high, ndc);
        }
        const glm::dvec2 offset = 0.5 * (low + high);
        fit.target += glm::transpose(rotation) * glm::dvec3(offset.x * tanX * fit.distance,
                                                            offset.y * tanY * fit.distance, 0.0);
    }
    fit.distance = boxFramingDistance(bounds, fit.target, rotation, tanX, tanY, radius);
    return fit;
}

}  // namespace

OrbitFrame orbitFrame(UpAxis up) {
    // The side is +X for all three, so that a frame's right-handed: side x up = front.
    switch (up) {
        case UpAxis::Y:
            return {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
        case UpAxis::Z:
            return {{0, 0, 1}, {0, -1, 0}, {1, 0, 0}};
        case UpAxis::NegativeY:
            return {{0, -1, 0}, {0, 0, -1}, {1, 0, 0}};
    }
    throw Error("unknown up axis");
}

glm::dvec2 orbitAngles(const glm::dvec3& towardsEye, UpAxis up) {
    const glm::dvec3 direction = glm::normalize(towardsEye);
    const OrbitFrame frame = orbitFrame(up);
    const double yaw =
        std::atan2(glm::dot(direction, frame.side), glm::dot(direction, frame.front));
    const double along = glm::dot(direction, frame.up);
    return glm::degrees(glm::dvec2(yaw, std::asin(std::clamp(along, -1.0, 1.0))));
}

Camera orbitCamera(const Bounds& bounds, const OrbitView& orbit, int width, int height,
                   double fovyDegrees) {
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.fovyDegrees = fovyDegrees;

    const glm::dvec3 middle = bounds.center();
    const glm::dvec3 center = orbit.center.value_or(middle);
    // A flat or single-point cloud still needs a finite radius to frame.
    const double radius =
        std::max(0.5 * glm::length(bounds.extent()), 1e-9 * (1.0 + glm::length(middle)));
    const double halfFovy = 0.5 * glm::radians(fovyDegrees);
    const double halfFovx =
        std::atan(std::tan(halfFovy) * static_cast<double>(width) / static_cast<double>(height));
    const double yaw = glm::radians(orbit.yawDegrees);
    const double pitch = glm::radians(orbit.pitchDegrees);
    const OrbitFrame frame = orbitFrame(orbit.up);
    // From the centre towards the eye.
    const glm::dvec3 direction = std::sin(yaw) * std::cos(pitch) * frame.side +
                                 std::sin(pitch) * frame.up +
                                 std::cos(yaw) * std::cos(pitch) * frame.front;
    glm::dvec3 up = frame.up;
    // Looking straight down the up axis leaves lookAt without a horizon: tilt the up vector.
    if (std::abs(glm::dot(direction, up)) > 0.9999) {
        up = -frame.front;
    }
    constexpr double kMargin = 1.05;
    double distance = kMargin * radius / std::sin(std::min(halfFovy, halfFovx));
    glm::dvec3 target = center;
    if (orbit.distance) {
        distance = *orbit.distance;
    } else if (orbit.framing == Framing::Box && !bounds.empty()) {
        const BoxFit fit = fitBox(orbit.framed.value_or(bounds), center,
                                  glm::dmat3(glm::lookAt(direction, glm::dvec3(0.0), up)),
                                  std::tan(halfFovx), std::tan(halfFovy), radius);
        target = fit.target;
        distance = fit.distance;
    }
    camera.view = glm::lookAt(target + distance * direction, target, up);

    // Near and far hug the bounding sphere, wherever the orbited point lies: its middle is this
    // deep along the line of sight, and no point of it is more than `radius` nearer or farther.
    const double toMiddle = glm::dot(target + distance * direction - middle, direction);
    const double margin = 0.02 * radius;
    camera.farPlane = toMiddle + radius + margin;
    camera.nearPlane = std::max(toMiddle - radius - margin, 1e-4 * camera.farPlane);
    return camera;
}

glm::dvec3 pixelCentreDirection(const Camera& camera, int x, int y) {
    const double focal = camera.focalLengthPixels();
    return {(x + 0.5 - 0.5 * camera.width) / focal, (0.5 * camera.height - (y + 0.5)) / focal,
            -1.0};
}

UpAxis upAxisFor(std::string_view up, std::string_view format) {
    if (up == "-y") {
        return UpAxis::NegativeY;
    }
    if (up != "auto" && up != "y" && up != "z") {
        throw Error(fmt::format("up '{}' is not auto, y, z or -y", up));
    }
    return up == "z" || (up == "auto" && format == "las") ? UpAxis::Z : UpAxis::Y;
}

}  // namespace subscan
