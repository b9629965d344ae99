#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "scan/Marble.h"
#include "scan/Scene.h"
#include "scan/SignedDistance.h"
#include "scan/SignedDistanceScene.h"

namespace subscan {

namespace {

Bounds boxBounds(const glm::dvec3& min, const glm::dvec3& max) {
    Bounds bounds;
    bounds.add(min);
    bounds.add(max);
    return bounds;
}

/// The unit sphere at the origin, intersected in closed form.
class SphereScene final : public Scene {
  public:
    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const override {
        // |o + t d|^2 = 1 with |d| = 1: t^2 + 2 b t + c = 0.
        const double b = glm::dot(ray.origin, ray.direction);
        const double c = glm::dot(ray.origin, ray.origin) - 1.0;
        const double discriminant = b * b - c;
        if (discriminant < 0.0) {
            return std::nullopt;
        }
        const double root = std::sqrt(discriminant);
        // The nearer root unless the origin is inside (or past the sphere).
        const double distance = -b - root >= 0.0 ? -b - root : -b + root;
        if (distance < 0.0 || distance >= maxDistance) {
            return std::nullopt;
        }
        const glm::dvec3 normal = glm::normalize(ray.origin + distance * ray.direction);
        return SurfaceHit{distance, facingRay(normal, ray.direction), kAlbedo};
    }
    Bounds bounds() const override { return boxBounds(glm::dvec3(-1.0), glm::dvec3(1.0)); }
    double surfaceDistance(const glm::dvec3& p) const override {
        return std::abs(glm::length(p) - 1.0);
    }

  private:
    static constexpr glm::vec3 kAlbedo{0.80f, 0.74f, 0.62f};  // warm white, like wax
};

/// A 27 cm ring around the Y axis.
class TorusScene final : public SignedDistanceScene {
  public:
    TorusScene()
        : SignedDistanceScene(boxBounds({-kMajor - kMinor, -kMinor, -kMajor - kMinor},
                                        {kMajor + kMinor, kMinor, kMajor + kMinor})) {}
    double signedDistance(const glm::dvec3& p) const override {
        return sdf::torusY(p, kMajor, kMinor);
    }

  protected:
    glm::dvec3 outwardNormal(const glm::dvec3& p) const override {
        // Away from the nearest point of the tube's centre circle.
        const glm::dvec2 radial(p.x, p.z);
        const double length = glm::length(radial);
        const glm::dvec2 onCircle =
            length > 0.0 ? radial * (kMajor / length) : glm::dvec2(kMajor, 0);
        return glm::normalize(p - glm::dvec3(onCircle.x, 0.0, onCircle.y));
    }
    glm::vec3 albedo(const glm::dvec3&) const override { return {0.22f, 0.50f, 0.30f}; }  // jade

  private:
    static constexpr double kMajor = 0.1;
    static constexpr double kMinor = 0.035;
};

/// A 20 x 12 x 10 cm block, pierced along Z by a 6 cm hole, with a 5 x 4 cm step cut out of the
/// top right edge: convex and concave right-angled edges and a through hole.
class BoxWithHoleScene final : public SignedDistanceScene {
  public:
    BoxWithHoleScene() : SignedDistanceScene(boxBounds(-kHalfExtents, kHalfExtents)) {}
    double signedDistance(const glm::dvec3& p) const override {
        const double block = sdf::box(p, kHalfExtents);
        const double hole = sdf::cylinderZ(p, kHoleAxis, kHoleRadius);
        // The step: everything with x > 0.05 and y > 0.02 (a box reaching past the block).
        const double step = sdf::box(p - glm::dvec3(0.1, 0.06, 0.0), glm::dvec3(0.05, 0.04, 0.1));
        return sdf::subtraction(sdf::subtraction(block, hole), step);
    }

  protected:
    glm::vec3 albedo(const glm::dvec3&) const override { return {0.72f, 0.72f, 0.70f}; }  // plaster

  private:
    static constexpr glm::dvec3 kHalfExtents{0.1, 0.06, 0.05};
    static constexpr glm::dvec2 kHoleAxis{-0.02, 0.0};
    static constexpr double kHoleRadius = 0.03;
};

/// The demo object: a white marble bowl holding an orb, circled by a thin tilted ring, on a
/// tapered stem braced by three thin fins, standing on a dark green plinth with a carved groove.
/// 0.29 m tall, base at y = 0, Y up. What it exercises:
///  - thin parts: the ring's tube is 5.6 mm across (1.9 % of the height), the fins 4 mm thick;
///  - concavities: the inside of the bowl, the narrow gap between orb and bowl, the groove around
///    the plinth, the fillets where stem meets plinth and bowl;
///  - self-occlusion: the ring shadows the bowl, the bowl's rim hides most of the orb from the low
///    views, the fins hide parts of the stem and of each other.
/// All parts are exact distance functions joined by 1-Lipschitz unions, so |f| bounds the
/// distance to the surface from below and is 0 on it.
class SculptureScene final : public SignedDistanceScene {
  public:
    SculptureScene()
        : SignedDistanceScene(boxBounds({-0.099, -0.0, -0.087}, {0.099, 0.294, 0.087})),
          whiteMarble_(0.09, MarbleAlbedo::kWhite),
          verdeMarble_(0.05, MarbleAlbedo::kVerde) {
        for (int fin = 0; fin < kFinCount; ++fin) {
            const double angle = std::numbers::pi * (0.5 + 2.0 * fin / kFinCount);
            finDirections_[static_cast<std::size_t>(fin)] = {std::cos(angle), std::sin(angle)};
        }
    }

    double signedDistance(const glm::dvec3& p) const override {
        // Plinth: a rounded drum 16 cm wide, 3.5 cm high, with a groove carved around its side.
        const double drum = sdf::roundedCylinderY(p - glm::dvec3(0.0, kPlinthTop / 2, 0.0), 0.08,
                                                  kPlinthTop / 2, 0.004);
        const double groove = sdf::torusY(p - glm::dvec3(0.0, kPlinthTop / 2, 0.0), 0.08, 0.005);
        const double plinth = sdf::smoothSubtraction(drum, groove, 0.002);

        // Stem: a cone frustum from the plinth (r 2.8 cm) up into the bowl (r 1.6 cm).
        const double stem = sdf::cappedConeY(p - glm::dvec3(0.0, 0.1, 0.0), 0.07, 0.028, 0.016);

        // Bowl: a 7 mm shell of mid radius 8.15 cm, cut 1 cm below its centre.
        const glm::dvec3 fromBowl = p - kBowlCentre;
        const double bowl = sdf::bowl(fromBowl, 0.0815, -0.01, 0.0035);
        const double orb = sdf::sphere(p - kOrbCentre, 0.042);

        // Ring: a torus tilted 35 degrees about X, touching the rim where two knobs hold it.
        const glm::dvec3 fromRing = p - kRingCentre;
        const double c = std::cos(kRingTilt), s = std::sin(kRingTilt);
        const glm::dvec3 inRingFrame(fromRing.x, c * fromRing.y + s * fromRing.z,
                                     -s * fromRing.y + c * fromRing.z);
        const double ring = sdf::torusY(inRingFrame, kRingRadius, kRingTube);
        const double knobs = std::min(sdf::sphere(fromRing - glm::dvec3(0.0895, 0.0, 0.0), 0.0075),
                                      sdf::sphere(fromRing + glm::dvec3(0.0895, 0.0, 0.0), 0.0075));

        double shape = sdf::smoothUnion(plinth, stem, 0.015);
        shape = sdf::smoothUnion(shape, finsDistance(p, fromBowl), 0.003);
        shape = sdf::smoothUnion(shape, bowl, 0.012);
        shape = sdf::smoothUnion(shape, orb, 0.006);
        shape = sdf::smoothUnion(shape, knobs, 0.003);
        return std::min(shape, ring);
    }

  protected:
    glm::vec3 albedo(const glm::dvec3& p) const override {
        // Two stones; the seam is just above the plinth's flat top, so the top face is all one
        // stone and the seam runs round the fillet.
        return p.y < kPlinthTop + kSeamAbovePlinth ? verdeMarble_(p) : whiteMarble_(p);
    }

  private:
    /// Three buttresses between plinth and bowl, 4 mm thick. Each is a plate in a vertical plane
    /// through the axis whose outer edge is a concave arc (radius 16 cm) from the plinth's edge up
    /// to under the bowl; where a fin reaches into the bowl it is cut back to the bowl's wall.
    double finsDistance(const glm::dvec3& p, const glm::dvec3& fromBowl) const {
        double fins = std::numeric_limits<double>::infinity();
        for (const glm::dvec2& direction : finDirections_) {
            const double along = p.x * direction.x + p.z * direction.y;
            const double across = -p.x * direction.y + p.z * direction.x;
            const glm::dvec2 inPlane(along, p.y);
            const double plate =
                sdf::box2(inPlane - glm::dvec2(0.0375, 0.115), glm::dvec2(0.0375, 0.085));
            const double outsideArc = 0.16 - glm::length(inPlane - glm::dvec2(0.187, 0.147));
            fins = std::min(fins, sdf::extrude(std::max(plate, outsideArc), across, 0.002));
        }
        // Cut at 8 cm from the bowl's centre, inside its 7.8-8.5 cm wall.
        return sdf::subtraction(fins, sdf::sphere(fromBowl, 0.080));
    }

    static constexpr int kFinCount = 3;
    static constexpr double kPlinthTop = 0.035;
    static constexpr double kSeamAbovePlinth = 0.0005;
    static constexpr glm::dvec3 kBowlCentre{0.0, 0.245, 0.0};
    static constexpr glm::dvec3 kOrbCentre{0.0, 0.205, 0.0};
    static constexpr glm::dvec3 kRingCentre{0.0, 0.235, 0.0};
    static constexpr double kRingTilt = 35.0 * std::numbers::pi / 180.0;
    static constexpr double kRingRadius = 0.095;
    static constexpr double kRingTube = 0.0028;

    MarbleAlbedo whiteMarble_;
    MarbleAlbedo verdeMarble_;
    std::array<glm::dvec2, kFinCount> finDirections_{};
};

constexpr std::array<std::string_view, 4> kSceneNames{"sphere", "torus", "box-with-hole",
                                                      "sculpture"};

}  // namespace

std::span<const std::string_view> builtInSceneNames() {
    return kSceneNames;
}

std::unique_ptr<Scene> makeBuiltInScene(std::string_view name) {
    if (name == "sphere") {
        return std::make_unique<SphereScene>();
    }
    if (name == "torus") {
        return std::make_unique<TorusScene>();
    }
    if (name == "box-with-hole") {
        return std::make_unique<BoxWithHoleScene>();
    }
    if (name == "sculpture") {
        return std::make_unique<SculptureScene>();
    }
    throw Error(fmt::format("there is no built-in scene '{}' (available: {})", name,
                            fmt::join(kSceneNames, ", ")));
}

}  // namespace subscan
