#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "scan/Scene.h"

namespace subscan::test {

/// The plane y = 0 within |x|, |z| <= halfExtent, facing +y (seen from above only): a true
/// surface whose depth has a closed form anywhere in a pixel.
class GroundRectangle final : public Scene {
  public:
    explicit GroundRectangle(double halfExtent) : halfExtent_(halfExtent) {}

    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const override {
        if (ray.direction.y >= 0.0 || ray.origin.y <= 0.0) {
            return std::nullopt;
        }
        const double distance = -ray.origin.y / ray.direction.y;
        const glm::dvec3 hit = ray.origin + distance * ray.direction;
        if (distance >= maxDistance || std::abs(hit.x) > halfExtent_ ||
            std::abs(hit.z) > halfExtent_) {
            return std::nullopt;
        }
        return SurfaceHit{distance, {0.0, 1.0, 0.0}, glm::vec3(0.5f)};
    }
    Bounds bounds() const override {
        Bounds box;
        box.add(glm::dvec3(-halfExtent_, 0.0, -halfExtent_));
        box.add(glm::dvec3(halfExtent_, 0.0, halfExtent_));
        return box;
    }
    double surfaceDistance(const glm::dvec3& p) const override {
        const double outside = std::hypot(std::max(std::abs(p.x) - halfExtent_, 0.0),
                                          std::max(std::abs(p.z) - halfExtent_, 0.0));
        return std::hypot(p.y, outside);
    }

  private:
    double halfExtent_;
};

}  // namespace subscan::test
