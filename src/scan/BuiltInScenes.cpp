#include <algorithm>
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

/// The buildings, tree and cars of the outdoor scene (everything but its ground), Y up, metres,
/// the ground's top at y = 0. Every part reaches 0.3 m below the ground, so the union with the
/// ground slab has no seams.
class OutdoorStructures final : public SignedDistanceScene {
  public:
    OutdoorStructures()
        : SignedDistanceScene(boxBounds({-25.0, -0.5, -25.0}, {25.0, 13.0, 25.0})) {}

    double signedDistance(const glm::dvec3& p) const override {
        double nearest = std::numeric_limits<double>::infinity();
        for (const Part part : kParts) {
            nearest = std::min(nearest, partDistance(part, p));
        }
        return nearest;
    }

  protected:
    glm::vec3 albedo(const glm::dvec3& p) const override {
        Part closest = Part::Office;
        double nearest = std::numeric_limits<double>::infinity();
        for (const Part part : kParts) {
            const double distance = partDistance(part, p);
            if (distance < nearest) {
                nearest = distance;
                closest = part;
            }
        }
        switch (closest) {
            case Part::Office:
                return {0.62f, 0.60f, 0.55f};  // concrete
            case Part::HouseWalls:
                return {0.78f, 0.72f, 0.60f};  // render
            case Part::HouseRoof:
                return {0.45f, 0.16f, 0.10f};  // clay tiles
            case Part::GardenWall:
                return {0.55f, 0.30f, 0.22f};  // brick
            case Part::Tower:
                return {0.40f, 0.44f, 0.50f};  // glass and steel
            case Part::Tree:
                return p.y < kCrownBottom ? glm::vec3(0.30f, 0.20f, 0.12f)   // bark
                                          : glm::vec3(0.16f, 0.36f, 0.12f);  // leaves
            case Part::CarBehindWall:
            case Part::CarInOpen:
                return {0.15f, 0.25f, 0.55f};  // blue paint
        }
        return {0.5f, 0.5f, 0.5f};
    }

  private:
    enum class Part {
        Office,
        HouseWalls,
        HouseRoof,
        GardenWall,
        Tower,
        Tree,
        CarBehindWall,
        CarInOpen
    };
    static constexpr std::array<Part, 8> kParts{
        Part::Office, Part::HouseWalls, Part::HouseRoof,     Part::GardenWall,
        Part::Tower,  Part::Tree,       Part::CarBehindWall, Part::CarInOpen};

    /// A box standing on the ground from y = -0.3 to `top`, centred on (x, z).
    static double standingBox(const glm::dvec3& p, double x, double z, double halfX, double halfZ,
                              double top) {
        const double halfHeight = 0.5 * (top + kBuried);
        return sdf::box(p - glm::dvec3(x, top - halfHeight, z),
                        glm::dvec3(halfX, halfHeight, halfZ));
    }

    static double partDistance(Part part, const glm::dvec3& p) {
        switch (part) {
            case Part::Office:  // a flat-roofed block, 12 x 8 x 9 m
                return standingBox(p, -13.0, -11.0, 6.0, 4.0, 9.0);
            case Part::HouseWalls:  // 8 x 6 m, walls 4 m high
                return standingBox(p, 12.0, -10.0, 4.0, 3.0, 4.0);
            case Part::HouseRoof: {
                // A gable roof with its ridge along X at 6.5 m, overhanging the walls by 0.3 m:
                // a slab cut by the two roof planes (each a unit-normal half-space, so their
                // maximum is a distance bound).
                const glm::dvec3 fromRidge = p - glm::dvec3(12.0, kRidgeHeight, -10.0);
                const double slope = (kRidgeHeight - kEavesHeight) / kRoofHalfWidth;
                const double underPlanes =
                    (fromRidge.y + slope * std::abs(fromRidge.z)) / std::sqrt(1.0 + slope * slope);
                const double slab =
                    sdf::box(p - glm::dvec3(12.0, 0.5 * (kRidgeHeight + kEavesHeight), -10.0),
                             glm::dvec3(4.3, 0.5 * (kRidgeHeight - kEavesHeight), kRoofHalfWidth));
                return std::max(slab, underPlanes);
            }
            case Part::GardenWall:  // free standing, 10 m long, 2.5 m high, 12 cm thick
                return standingBox(p, 0.0, 8.0, 5.0, 0.06, 2.5);
            case Part::Tower:  // a 12 m block far from the middle: sparse rings on its walls
                return standingBox(p, -20.0, 18.0, 4.0, 5.0, 12.0);
            case Part::Tree: {
                const double trunk =
                    sdf::roundedCylinderY(p - glm::dvec3(9.0, 1.5, 7.0), 0.2, 1.8, 0.02);
                double crown = sdf::sphere(p - glm::dvec3(9.0, 4.8, 7.0), 1.8);
                crown =
                    sdf::smoothUnion(crown, sdf::sphere(p - glm::dvec3(8.2, 5.6, 7.6), 1.3), 0.6);
                crown =
                    sdf::smoothUnion(crown, sdf::sphere(p - glm::dvec3(9.8, 5.4, 6.4), 1.2), 0.6);
                return sdf::smoothUnion(trunk, crown, 0.3);
            }
            case Part::CarBehindWall:  // hidden from the middle of the scene by the garden wall
                return roundedCar(p, glm::dvec3(0.0, 0.0, 12.0), glm::dvec3(2.25, 0.0, 0.9));
            case Part::CarInOpen:
                return roundedCar(p, glm::dvec3(-7.0, 0.0, 4.0), glm::dvec3(0.9, 0.0, 2.25));
        }
        return std::numeric_limits<double>::infinity();
    }

    /// A 1.5 m high box with 10 cm rounded edges standing on the ground at `base`, half
    /// footprint `half` (x and z).
    static double roundedCar(const glm::dvec3& p, const glm::dvec3& base, const glm::dvec3& half) {
        constexpr double kRounding = 0.1;
        constexpr double kHeight = 1.5;
        const double halfHeight = 0.5 * (kHeight + kBuried);
        return sdf::box(p - base - glm::dvec3(0.0, kHeight - halfHeight, 0.0),
                        glm::dvec3(half.x, halfHeight, half.z) - kRounding) -
               kRounding;
    }

    static constexpr double kBuried = 0.3;
    static constexpr double kEavesHeight = 4.0;
    static constexpr double kRidgeHeight = 6.5;
    static constexpr double kRoofHalfWidth = 3.3;
    static constexpr double kCrownBottom = 3.2;
};

/// The outdoor scene's ground slab: 60 x 60 m, 1 m thick, its top at y = 0.
constexpr glm::dvec3 kGroundHalfExtents{30.0, 0.5, 30.0};

double groundDistance(const glm::dvec3& p) {
    return sdf::box(p + glm::dvec3(0.0, kGroundHalfExtents.y, 0.0), kGroundHalfExtents);
}

/// The ground and the structures as one signed distance: what a ray starting inside either
/// solid is traced through, since leaving one may mean entering the other (a buried footing).
class OutdoorUnion final : public SignedDistanceScene {
  public:
    OutdoorUnion(const OutdoorStructures& structures, const Bounds& bounds)
        : SignedDistanceScene(bounds), structures_(structures) {}
    double signedDistance(const glm::dvec3& p) const override {
        return std::min(groundDistance(p), structures_.signedDistance(p));
    }

  protected:
    glm::vec3 albedo(const glm::dvec3&) const override { return {0.30f, 0.30f, 0.31f}; }

  private:
    const OutdoorStructures& structures_;
};

/// A 60 x 60 m outdoor scene for LiDAR (see makeBuiltInScene): a flat ground slab intersected
/// in closed form (sphere tracing would crawl along it at grazing angles), and
/// OutdoorStructures standing on it. The union of two closed solids is closed. From outside
/// both, the nearer of the two first hits is the union's; a ray starting inside is traced
/// through their union's signed distance (scanners and cameras stand outside).
class OutdoorScene final : public Scene {
  public:
    OutdoorScene() : union_(structures_, unionBounds(structures_)) {}

    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const override {
        if (union_.signedDistance(ray.origin) < 0.0) {
            return union_.intersect(ray, maxDistance);
        }
        std::optional<SurfaceHit> ground = intersectGround(ray, maxDistance);
        std::optional<SurfaceHit> structure =
            structures_.intersect(ray, ground ? ground->distance : maxDistance);
        return structure ? structure : ground;
    }
    Bounds bounds() const override { return union_.bounds(); }
    double surfaceDistance(const glm::dvec3& p) const override { return union_.surfaceDistance(p); }

  private:
    static Bounds unionBounds(const OutdoorStructures& structures) {
        Bounds bounds = structures.bounds();
        bounds.add(-kGroundHalfExtents - glm::dvec3(0.0, kGroundHalfExtents.y, 0.0));
        bounds.add(kGroundHalfExtents - glm::dvec3(0.0, kGroundHalfExtents.y, 0.0));
        return bounds;
    }

    /// The slab method: the ray is inside the box between its last entry into and first exit
    /// from the three slabs; the face of the last entry (or, from inside, the first exit) is hit.
    static std::optional<SurfaceHit> intersectGround(const Ray& ray, double maxDistance) {
        const glm::dvec3 centre(0.0, -kGroundHalfExtents.y, 0.0);
        double enter = -std::numeric_limits<double>::infinity();
        double leave = std::numeric_limits<double>::infinity();
        int enterAxis = 0, leaveAxis = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const double origin = ray.origin[axis] - centre[axis];
            const double direction = ray.direction[axis];
            const double half = kGroundHalfExtents[axis];
            if (direction == 0.0) {
                if (std::abs(origin) > half) {
                    return std::nullopt;
                }
                continue;
            }
            const double near = std::min((-half - origin) / direction, (half - origin) / direction);
            const double far = std::max((-half - origin) / direction, (half - origin) / direction);
            if (near > enter) {
                enter = near;
                enterAxis = axis;
            }
            if (far < leave) {
                leave = far;
                leaveAxis = axis;
            }
        }
        if (enter > leave || leave < 0.0) {
            return std::nullopt;
        }
        const bool fromInside = enter < 0.0;
        const double distance = fromInside ? leave : enter;
        if (distance >= maxDistance) {
            return std::nullopt;
        }
        const int axis = fromInside ? leaveAxis : enterAxis;
        glm::dvec3 normal(0.0);
        normal[axis] = ray.direction[axis] > 0.0 ? -1.0 : 1.0;
        const glm::dvec3 point = ray.origin + distance * ray.direction;
        return SurfaceHit{distance, normal, groundAlbedo(point)};
    }

    /// Asphalt in the middle, grass around it.
    static glm::vec3 groundAlbedo(const glm::dvec3& p) {
        constexpr double kPlazaHalfWidth = 16.0;
        return std::max(std::abs(p.x), std::abs(p.z)) < kPlazaHalfWidth
                   ? glm::vec3(0.30f, 0.30f, 0.31f)
                   : glm::vec3(0.20f, 0.34f, 0.14f);
    }

    OutdoorStructures structures_;
    OutdoorUnion union_;  // refers to structures_, declared before it
};

constexpr std::array<std::string_view, 5> kSceneNames{"sphere", "torus", "box-with-hole",
                                                      "sculpture", "outdoor"};

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
    if (name == "outdoor") {
        return std::make_unique<OutdoorScene>();
    }
    throw Error(fmt::format("there is no built-in scene '{}' (available: {})", name,
                            fmt::join(kSceneNames, ", ")));
}

}  // namespace subscan
