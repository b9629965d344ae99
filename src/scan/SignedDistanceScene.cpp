#include "scan/SignedDistanceScene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>

#include "core/Error.h"

namespace subscan {

namespace {

/// Enough for rays that graze a surface over a long stretch; a ray that still has not crossed
/// by then is taken as a miss (it only ever came within the minimum step of the surface).
constexpr int kMaxSteps = 4096;
constexpr double kMinimumStepFraction = 1e-6;
constexpr double kBracketFraction = 1e-11;
constexpr double kBoundsPaddingFraction = 1e-4;

/// The parameter interval where the ray is inside the box, or nullopt.
std::optional<std::pair<double, double>> clipToBox(const Ray& ray, const Bounds& box) {
    double enter = 0.0;
    double leave = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
        const double origin = ray.origin[axis];
        const double direction = ray.direction[axis];
        if (direction == 0.0) {
            if (origin < box.min[axis] || origin > box.max[axis]) {
                return std::nullopt;
            }
            continue;
        }
        double near = (box.min[axis] - origin) / direction;
        double far = (box.max[axis] - origin) / direction;
        if (near > far) {
            std::swap(near, far);
        }
        enter = std::max(enter, near);
        leave = std::min(leave, far);
    }
    if (enter > leave) {
        return std::nullopt;
    }
    return std::pair{enter, leave};
}

}  // namespace

SignedDistanceScene::SignedDistanceScene(const Bounds& bounds)
    : bounds_(bounds), size_(glm::length(bounds.extent())) {
    if (bounds.empty() || !(size_ > 0.0)) {
        throw Error("a signed distance scene needs non-empty bounds");
    }
}

double SignedDistanceScene::surfaceDistance(const glm::dvec3& p) const {
    return std::abs(signedDistance(p));
}

std::optional<SurfaceHit> SignedDistanceScene::intersect(const Ray& ray, double maxDistance) const {
    Bounds padded = bounds_;
    padded.min -= kBoundsPaddingFraction * size_;
    padded.max += kBoundsPaddingFraction * size_;
    const auto interval = clipToBox(ray, padded);
    if (!interval) {
        return std::nullopt;
    }
    const double end = std::min(interval->second, maxDistance);
    const double minimumStep = kMinimumStepFraction * size_;
    auto valueAt = [&](double t) { return signedDistance(ray.origin + t * ray.direction); };

    double t = interval->first;
    if (t >= end) {
        return std::nullopt;
    }
    double value = valueAt(t);
    // A ray starting inside the solid looks for where it leaves.
    const bool startsInside = value < 0.0;
    for (int step = 0; step < kMaxSteps; ++step) {
        if (t >= end) {
            return std::nullopt;
        }
        const double before = t;
        const double valueBefore = value;
        t = std::min(t + std::max(std::abs(value), minimumStep), end);
        value = valueAt(t);
        if ((value < 0.0) != startsInside) {
            const double distance = refineCrossing(ray, before, valueBefore, t, value);
            if (distance >= maxDistance) {
                return std::nullopt;
            }
            const glm::dvec3 point = ray.origin + distance * ray.direction;
            SurfaceHit hit;
            hit.distance = distance;
            // The finite-difference gradient can average two faces at a crease into a normal
            // that faces away from the ray that just entered through one of them.
            hit.normal = facingRay(outwardNormal(point), ray.direction);
            hit.albedo = albedo(point);
            return hit;
        }
    }
    return std::nullopt;
}

double SignedDistanceScene::refineCrossing(const Ray& ray, double before, double valueBefore,
                                           double after, double valueAfter) const {
    // Illinois regula falsi: secant steps, halving the weight of an end that is kept twice so
    // both ends converge; every few steps a bisection guarantees progress.
    double a = before, fa = valueBefore;
    double b = after, fb = valueAfter;
    const double tolerance = kBracketFraction * size_;
    int keptSide = 0;
    for (int iteration = 0; iteration < 100 && std::abs(b - a) > tolerance; ++iteration) {
        double c = iteration % 4 == 3 ? 0.5 * (a + b) : (a * fb - b * fa) / (fb - fa);
        if (!(c > std::min(a, b) && c < std::max(a, b))) {
            c = 0.5 * (a + b);
        }
        const double fc = signedDistance(ray.origin + c * ray.direction);
        if (fc == 0.0) {
            return c;
        }
        if ((fc < 0.0) == (fb < 0.0)) {
            b = c;
            fb = fc;
            if (keptSide == -1) {
                fa *= 0.5;
            }
            keptSide = -1;
        } else {
            a = c;
            fa = fc;
            if (keptSide == 1) {
                fb *= 0.5;
            }
            keptSide = 1;
        }
    }
    return 0.5 * (a + b);
}

glm::dvec3 SignedDistanceScene::outwardNormal(const glm::dvec3& p) const {
    // Step 1e-7 of the size: f is computed to ~1e-16 of the size, so the gradient is accurate to
    // ~1e-9, and curvature errors (step squared) are smaller still.
    const double step = 1e-7 * size_;
    const glm::dvec3 gradient(
        signedDistance(p + glm::dvec3(step, 0, 0)) - signedDistance(p - glm::dvec3(step, 0, 0)),
        signedDistance(p + glm::dvec3(0, step, 0)) - signedDistance(p - glm::dvec3(0, step, 0)),
        signedDistance(p + glm::dvec3(0, 0, step)) - signedDistance(p - glm::dvec3(0, 0, step)));
    const double length = glm::length(gradient);
    return length > 0.0 ? gradient / length : glm::dvec3(0.0, 1.0, 0.0);
}

}  // namespace subscan
