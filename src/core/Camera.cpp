#include "core/Camera.h"

#include <algorithm>
#include <array>
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

struct BoxFit {
    glm::dvec3 target;
    double distance;
};

/// Frames the box's corners, the view's direction kept: the least eye distance at which some
/// move of the target across the line of sight puts every corner within 95 % of the half-fields
/// (tangents `tanX`, `tanY`), and that move, centring the corners' projection. In view axes
/// (`rotation`: world to view) a corner at (x, y, z) from the target lies d - z deep, so a move
/// by a along x keeps it inside when |x - a| <= c (d - z), c = 0.95 tanX: some a serves every
/// corner when x_i - x_j <= c (2 d - z_i - z_j) for every pair, the least d is the largest of
/// those bounds (and y's), and then the corners' extremes meet the border together on the
/// limiting axis. On the other the move centres them: their largest and smallest tangent
/// (x - a) / (d - z) sum to 0, found by bisection (the sum falls as a grows). Exact at any
/// field of view; moving the target by the projection's offset, as before, did not converge
/// where near corners dominate (a 90 degree field left the bunny's box at -0.96..0.75, wider
/// ones in a corner of the picture). At least a hundredth of `radius` in front of the nearest
/// corner, for a box that is flat towards the eye.
BoxFit fitBox(const Bounds& bounds, const glm::dvec3& center, const glm::dmat3& rotation,
              double tanX, double tanY, double radius) {
    constexpr double kFill = 0.95;
    std::array<glm::dvec3, 8> corners;
    for (int corner = 0; corner < 8; ++corner) {
        corners[corner] = rotation * (bounds.corner(corner) - center);
    }
    const glm::dvec2 reach(kFill * tanX, kFill * tanY);
    double distance = -std::numeric_limits<double>::infinity();
    for (const glm::dvec3& i : corners) {
        distance = std::max(distance, i.z + 0.01 * radius);
        for (const glm::dvec3& j : corners) {
            const double depths = 0.5 * (i.z + j.z);
            distance = std::max({distance, (i.x - j.x) / (2.0 * reach.x) + depths,
                                 (i.y - j.y) / (2.0 * reach.y) + depths});
        }
    }
    glm::dvec2 move(0.0);
    for (int axis = 0; axis < 2; ++axis) {
        double low = -std::numeric_limits<double>::infinity();
        double high = std::numeric_limits<double>::infinity();
        for (const glm::dvec3& corner : corners) {
            low = std::max(low, corner[axis] - reach[axis] * (distance - corner.z));
            high = std::min(high, corner[axis] + reach[axis] * (distance - corner.z));
        }
        const auto extremes = [&](double a) {
            double largest = -std::numeric_limits<double>::infinity();
            double smallest = std::numeric_limits<double>::infinity();
            for (const glm::dvec3& corner : corners) {
                const double tangent = (corner[axis] - a) / (distance - corner.z);
                largest = std::max(largest, tangent);
                smallest = std::min(smallest, tangent);
            }
            return largest + smallest;
        };
        for (int step = 0; step < 64 && low < high; ++step) {
            const double middle = 0.5 * (low + high);
            (extremes(middle) > 0.0 ? low : high) = middle;
        }
        move[axis] = 0.5 * (low + high);
    }
    return {center + glm::transpose(rotation) * glm::dvec3(move, 0.0), distance};
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
    // Looking straight along the up axis leaves lookAt without a horizon: the picture's up is
    // then the limit it takes as the pitch nears ±90°, the yaw's horizontal direction away from
    // the eye looking down, towards it looking up, so the view still turns with the yaw.
    if (std::abs(glm::dot(direction, up)) > 0.9999) {
        up =
            (pitch > 0.0 ? -1.0 : 1.0) * (std::sin(yaw) * frame.side + std::cos(yaw) * frame.front);
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
