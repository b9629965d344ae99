#pragma once

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

/// Signed distance functions of primitives and their combinations (after Quilez,
/// https://iquilezles.org/articles/distfunctions/), in double. Negative inside. Every function
/// here is 1-Lipschitz, so |value| never exceeds the true distance to the zero set, which is what
/// sphere tracing needs; the primitives are exact distances.
namespace subscan::sdf {

inline double sphere(const glm::dvec3& p, double radius) {
    return glm::length(p) - radius;
}

/// Box centred on the origin.
inline double box(const glm::dvec3& p, const glm::dvec3& halfExtents) {
    const glm::dvec3 q = glm::abs(p) - halfExtents;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

/// 2-D box centred on the origin.
inline double box2(const glm::dvec2& p, const glm::dvec2& halfExtents) {
    const glm::dvec2 q = glm::abs(p) - halfExtents;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, q.y), 0.0);
}

/// Cylinder around the Y axis, y in [-halfHeight, halfHeight], edges rounded by `rounding`.
inline double roundedCylinderY(const glm::dvec3& p, double radius, double halfHeight,
                               double rounding) {
    const glm::dvec2 d = glm::abs(glm::dvec2(glm::length(glm::dvec2(p.x, p.z)), p.y)) -
                         glm::dvec2(radius - rounding, halfHeight - rounding);
    return std::min(std::max(d.x, d.y), 0.0) + glm::length(glm::max(d, 0.0)) - rounding;
}

/// Infinite cylinder along the Z axis through (x, y).
inline double cylinderZ(const glm::dvec3& p, const glm::dvec2& axis, double radius) {
    return glm::length(glm::dvec2(p.x, p.y) - axis) - radius;
}

/// Torus around the Y axis in the XZ plane.
inline double torusY(const glm::dvec3& p, double majorRadius, double minorRadius) {
    const glm::dvec2 q(glm::length(glm::dvec2(p.x, p.z)) - majorRadius, p.y);
    return glm::length(q) - minorRadius;
}

/// Cone frustum around the Y axis, y in [-halfHeight, halfHeight], radius `bottomRadius` at the
/// bottom and `topRadius` at the top.
inline double cappedConeY(const glm::dvec3& p, double halfHeight, double bottomRadius,
                          double topRadius) {
    const glm::dvec2 q(glm::length(glm::dvec2(p.x, p.z)), p.y);
    const glm::dvec2 k1(topRadius, halfHeight);
    const glm::dvec2 k2(topRadius - bottomRadius, 2.0 * halfHeight);
    const glm::dvec2 ca(q.x - std::min(q.x, q.y < 0.0 ? bottomRadius : topRadius),
                        std::abs(q.y) - halfHeight);
    const glm::dvec2 cb =
        q - k1 + k2 * std::clamp(glm::dot(k1 - q, k2) / glm::dot(k2, k2), 0.0, 1.0);
    const double sign = (cb.x < 0.0 && ca.y < 0.0) ? -1.0 : 1.0;
    return sign * std::sqrt(std::min(glm::dot(ca, ca), glm::dot(cb, cb)));
}

/// A spherical shell of mid radius `radius` and half thickness `halfThickness`, cut by the plane
/// y = `cutHeight` (relative to the centre), keeping the part below: a bowl with a rounded rim.
inline double bowl(const glm::dvec3& p, double radius, double cutHeight, double halfThickness) {
    const double rimRadius = std::sqrt(radius * radius - cutHeight * cutHeight);
    const glm::dvec2 q(glm::length(glm::dvec2(p.x, p.z)), p.y);
    const double toShell = cutHeight * q.x < rimRadius * q.y
                               ? glm::length(q - glm::dvec2(rimRadius, cutHeight))
                               : std::abs(glm::length(q) - radius);
    return toShell - halfThickness;
}

/// A 2-D shape with signed distance `d2` in the plane, extruded to a slab |z| <= halfThickness.
inline double extrude(double d2, double z, double halfThickness) {
    const glm::dvec2 w(d2, std::abs(z) - halfThickness);
    return std::min(std::max(w.x, w.y), 0.0) + glm::length(glm::max(w, 0.0));
}

/// Union with a fillet of size k (polynomial smooth minimum). Its gradient is a convex
/// combination of the two inputs' gradients, so it stays 1-Lipschitz.
inline double smoothUnion(double a, double b, double k) {
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

/// `a` with `b` carved out, the carved edge rounded by k.
inline double smoothSubtraction(double a, double b, double k) {
    return -smoothUnion(-a, b, k);
}

inline double subtraction(double a, double b) {
    return std::max(a, -b);
}

}  // namespace subscan::sdf
