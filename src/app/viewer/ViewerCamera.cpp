#include "app/viewer/ViewerCamera.h"

#include <algorithm>
#include <cmath>

#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

namespace subscan::viewer {

namespace {

// orbitCamera's defaults: the auto-framed view `R` returns to.
const OrbitView kDefaultOrbit;

// The closest and farthest the eye may come to its centre, in scene radii: zooming stops
// before the view matrix loses precision or the scene shrinks to nothing.
constexpr double kMinDistanceRadii = 1e-5;
constexpr double kMaxDistanceRadii = 1e4;

double focalLengthPixels(int height) {
    return 0.5 * static_cast<double>(height) /
           std::tan(0.5 * glm::radians(ViewerCamera::kFovyDegrees));
}

}  // namespace

ViewerCamera::ViewerCamera(const Bounds& bounds, UpAxis up, int width, int height,
                           std::optional<Bounds> framed)
    : bounds_(bounds), framed_(framed), up_(up) {
    // orbitCamera's radius, so that reset() reproduces it exactly.
    sceneRadius_ =
        std::max(0.5 * glm::length(bounds.extent()), 1e-9 * (1.0 + glm::length(bounds.center())));
    reset(width, height);
}

void ViewerCamera::reset(int width, int height) {
    yawDegrees_ = kDefaultOrbit.yawDegrees;
    pitchDegrees_ = kDefaultOrbit.pitchDegrees;
    frameAll(width, height);
}

void ViewerCamera::frameAll(int width, int height) {
    // orbitCamera's framing of the box from this direction, as render's default view: its eye,
    // and the point it looks at (the bounds' middle moved across the line of sight to centre
    // the picture) as the orbit's centre.
    const glm::dvec3 middle = bounds_.empty() ? glm::dvec3(0.0) : bounds_.center();
    OrbitView orbit{yawDegrees_, pitchDegrees_, std::nullopt, up_, middle, Framing::Box, framed_};
    const glm::dvec3 eye =
        orbitCamera(bounds_, orbit, std::max(width, 1), std::max(height, 1), kFovyDegrees).eye();
    distance_ = glm::dot(eye - middle, towardsEye());
    centre_ = eye - distance_ * towardsEye();
}

glm::dvec3 ViewerCamera::towardsEye() const {
    const double yaw = glm::radians(yawDegrees_);
    const double pitch = glm::radians(pitchDegrees_);
    const OrbitFrame frame = orbitFrame(up_);
    return std::sin(yaw) * std::cos(pitch) * frame.side + std::sin(pitch) * frame.up +
           std::cos(yaw) * std::cos(pitch) * frame.front;
}

glm::dvec3 ViewerCamera::eye() const {
    return centre_ + distance_ * towardsEye();
}

glm::dvec3 ViewerCamera::forward() const {
    return -towardsEye();
}

glm::dvec3 ViewerCamera::right() const {
    return glm::normalize(glm::cross(forward(), orbitFrame(up_).up));
}

glm::dvec3 ViewerCamera::up() const {
    return glm::cross(right(), forward());
}

void ViewerCamera::clampDistance() {
    distance_ =
        std::clamp(distance_, kMinDistanceRadii * sceneRadius_, kMaxDistanceRadii * sceneRadius_);
}

void ViewerCamera::orbit(double dxPixels, double dyPixels) {
    yawDegrees_ = std::remainder(yawDegrees_ - dxPixels * kDegreesPerPixel, 360.0);
    pitchDegrees_ = std::clamp(pitchDegrees_ + dyPixels * kDegreesPerPixel, -kMaxPitchDegrees,
                               kMaxPitchDegrees);
}

void ViewerCamera::pan(double dxPixels, double dyPixels, int viewportHeight) {
    const double unitsPerPixel = distance_ / focalLengthPixels(std::max(viewportHeight, 1));
    centre_ += (-dxPixels * right() + dyPixels * up()) * unitsPerPixel;
}

void ViewerCamera::zoomTowards(double steps, const glm::dvec3& target) {
    // Clamped as a factor: a huge step count underflows pow() to 0 or overflows it to inf.
    const double factor =
        std::clamp(std::pow(kZoomPerStep, steps), kMinDistanceRadii * sceneRadius_ / distance_,
                   kMaxDistanceRadii * sceneRadius_ / distance_);
    // Scaling eye and centre about the target keeps the direction and the target's pixel.
    centre_ = target + (centre_ - target) * factor;
    distance_ *= factor;
}

void ViewerCamera::look(double dxPixels, double dyPixels) {
    const glm::dvec3 fixedEye = eye();
    orbit(dxPixels, dyPixels);
    centre_ = fixedEye - distance_ * towardsEye();
}

void ViewerCamera::move(const glm::dvec3& rightUpBack) {
    centre_ += rightUpBack.x * right() + rightUpBack.y * up() + rightUpBack.z * towardsEye();
}

void ViewerCamera::setCentre(const glm::dvec3& point) {
    lookFrom(eye(), point);
}

void ViewerCamera::lookFrom(const glm::dvec3& eye, const glm::dvec3& target) {
    const glm::dvec3 fromTarget = eye - target;
    const double length = glm::length(fromTarget);
    if (!(length > kMinDistanceRadii * sceneRadius_)) {
        return;
    }
    const glm::dvec2 angles = orbitAngles(fromTarget, up_);
    yawDegrees_ = angles.x;
    pitchDegrees_ = std::clamp(angles.y, -kMaxPitchDegrees, kMaxPitchDegrees);
    centre_ = target;
    distance_ = length;
    clampDistance();
}

glm::dvec3 ViewerCamera::dragLight(const glm::dvec3& towardsLight, double dxPixels,
                                   double dyPixels) const {
    // The direction in the view's frame: x right, y up, z towards the eye.
    const glm::dvec3 x = right();
    const glm::dvec3 y = up();
    const glm::dvec3 z = towardsEye();
    glm::dvec3 view(glm::dot(towardsLight, x), glm::dot(towardsLight, y),
                    glm::dot(towardsLight, z));
    const double length = glm::length(view);
    view = length > 0.0 && std::isfinite(length) ? view / length : glm::dvec3(0.0, 0.0, 1.0);
    // Azimuth 0 faces the eye and grows to the right; elevation grows upwards (window y grows
    // downwards).
    const double azimuth = std::atan2(view.x, view.z) + glm::radians(dxPixels * kDegreesPerPixel);
    const double maxElevation = glm::radians(kMaxPitchDegrees);
    const double elevation = std::clamp(
        std::asin(std::clamp(view.y, -1.0, 1.0)) - glm::radians(dyPixels * kDegreesPerPixel),
        -maxElevation, maxElevation);
    const glm::dvec3 turned(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                            std::cos(elevation) * std::cos(azimuth));
    return glm::normalize(turned.x * x + turned.y * y + turned.z * z);
}

glm::dvec3 ViewerCamera::defaultLightDirection() const {
    return glm::normalize(-right() + up() + towardsEye());
}

Camera ViewerCamera::camera(int width, int height) const {
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.fovyDegrees = kFovyDegrees;
    const glm::dvec3 eyePosition = eye();
    camera.view = glm::lookAt(eyePosition, centre_, orbitFrame(up_).up);
    // orbitCamera's depth range, measured from wherever the eye is now: the bounding sphere's
    // middle lies this deep along the line of sight.
    const double toScene =
        bounds_.empty() ? distance_ : glm::dot(eyePosition - bounds_.center(), towardsEye());
    const double margin = 0.02 * sceneRadius_;
    camera.farPlane = toScene + sceneRadius_ + margin;
    camera.nearPlane = std::max(toScene - sceneRadius_ - margin, 1e-4 * camera.farPlane);
    return camera;
}

glm::dvec3 ViewerCamera::pointAtCentreDepth(const glm::dvec2& pixel, int width, int height) const {
    const double focal = focalLengthPixels(std::max(height, 1));
    const double x = (pixel.x - 0.5 * width) / focal;
    const double y = (0.5 * height - pixel.y) / focal;
    return eye() + distance_ * (forward() + x * right() + y * up());
}

glm::dvec3 ViewerCamera::unproject(const Camera& camera, const glm::dvec2& pixel, double depth) {
    const double focal = camera.focalLengthPixels();
    const glm::dvec4 inView(depth * (pixel.x - 0.5 * camera.width) / focal,
                            depth * (0.5 * camera.height - pixel.y) / focal, -depth, 1.0);
    return glm::dvec3(glm::inverse(camera.view) * inView);
}

}  // namespace subscan::viewer
