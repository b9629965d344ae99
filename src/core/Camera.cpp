#include "core/Camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

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
    if (jitterPixels == glm::dvec2(0.0)) {
        return projection;
    }
    // A shift in normalized device coordinates (2 / size per pixel; window y runs down): as a
    // translation of clip space it scales with w, so it moves every depth alike.
    const glm::dvec3 shift(2.0 * jitterPixels.x / width, -2.0 * jitterPixels.y / height, 0.0);
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
    constexpr double kMargin = 1.05;
    const double distance =
        orbit.distance.value_or(kMargin * radius / std::sin(std::min(halfFovy, halfFovx)));

    const double yaw = glm::radians(orbit.yawDegrees);
    const double pitch = glm::radians(orbit.pitchDegrees);
    glm::dvec3 direction;  // from the centre towards the eye
    glm::dvec3 up;
    if (orbit.up == UpAxis::Y) {
        direction = {std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                     std::cos(yaw) * std::cos(pitch)};
        up = {0, 1, 0};
    } else {
        direction = {std::sin(yaw) * std::cos(pitch), -std::cos(yaw) * std::cos(pitch),
                     std::sin(pitch)};
        up = {0, 0, 1};
    }
    // Looking straight down the up axis leaves lookAt without a horizon: tilt the up vector.
    if (std::abs(glm::dot(direction, up)) > 0.9999) {
        up = orbit.up == UpAxis::Y ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
    }
    camera.view = glm::lookAt(center + distance * direction, center, up);

    // Near and far hug the bounding sphere, wherever the orbited point lies.
    const double reach = radius + glm::length(center - middle);
    const double margin = 0.02 * radius;
    camera.farPlane = distance + reach + margin;
    camera.nearPlane = std::max(distance - reach - margin, 1e-4 * camera.farPlane);
    return camera;
}

}  // namespace subscan
