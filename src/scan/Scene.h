#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// A ray in scene coordinates (metres, double precision).
struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 direction{0.0, 0.0, -1.0};  // unit length
};

/// Where a ray first meets a surface.
struct SurfaceHit {
    double distance = 0.0;   // along the ray, from its origin
    glm::dvec3 normal{0.0};  // unit; outward, and never facing away from the ray (see Scene)
    glm::vec3 albedo{0.0f};  // linear RGB, 0..1
};

/// Geometry with exact ground truth, shared by the virtual scanner (which samples it) and the
/// quality evaluation (which renders it). Immutable after construction, so any number of threads
/// may query one scene at once.
///
/// Normals: closed analytic surfaces return the outward normal. Where a ray meets a surface from
/// behind (the inside of an open mesh) or where a normal averaged across a crease would face away
/// from the ray, the normal is turned to the ray's side, as a scanner can only see that side.
class Scene {
  public:
    virtual ~Scene() = default;

    /// The first surface along the ray with distance in [0, maxDistance), or nullopt.
    virtual std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const = 0;
    /// A box containing the whole surface.
    virtual Bounds bounds() const = 0;
    /// |distance| from p to the surface: exact, or a lower bound that is 0 exactly on it.
    virtual double surfaceDistance(const glm::dvec3& p) const = 0;
};

/// The names makeBuiltInScene accepts, in the order help texts list them.
std::span<const std::string_view> builtInSceneNames();

/// A built-in analytic scene, in metres with Y up:
///  - "sphere": unit radius, centred on the origin;
///  - "torus": ring of radius 0.1 and tube radius 0.035 around the Y axis (a 27 cm ring);
///  - "box-with-hole": a 20 x 12 x 10 cm block pierced along Z by a 6 cm hole, with a step cut
///    out of one top edge (concave edges, a through hole);
///  - "sculpture": a 29 cm marble sculpture on a plinth (see BuiltInScenes.cpp);
///  - "outdoor": for LiDAR, a 60 x 60 m ground (top at y = 0, the middle kept clear for a
///    station) with a flat-roofed block, a gable-roofed house, a free-standing 12 cm garden wall
///    with a car hidden behind it (seen from the middle), a tree, a second car and a distant
///    tower (see BuiltInScenes.cpp).
/// Throws subscan::Error listing the available names.
std::unique_ptr<Scene> makeBuiltInScene(std::string_view name);

/// What colours a mesh scene reports.
enum class AlbedoSource {
    VertexColors,  // the mesh's vertex colours interpolated over each triangle, else plain grey
    Marble,        // procedural marble, veins scaled to the mesh's size
    Grey,          // plain light grey
};

/// The triangles of `mesh` (positions in its file coordinates) with a bounding volume hierarchy.
/// Normals are area-weighted vertex normals interpolated across each triangle. The scene keeps its
/// own copy of what it needs. Throws subscan::Error when the mesh has no triangles.
std::unique_ptr<Scene> makeMeshScene(const PointCloud& mesh,
                                     AlbedoSource albedo = AlbedoSource::VertexColors);

/// `normal` turned to the side a ray with `direction` comes from: a normal facing away is
/// mirrored across the plane perpendicular to the ray, which keeps its tilt but makes it visible.
inline glm::dvec3 facingRay(const glm::dvec3& normal, const glm::dvec3& direction) {
    const double along = glm::dot(normal, direction);
    return along > 0.0 ? glm::normalize(normal - 2.0 * along * direction) : normal;
}

}  // namespace subscan
