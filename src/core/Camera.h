#pragma once

#include <optional>
#include <string_view>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// A pinhole camera in the conventions of DESIGN.md §4: right-handed, looking down -Z in view
/// space, Y up, OpenGL clip space. `view` maps the file's own coordinates to view space, in
/// double so that UTM-sized coordinates lose nothing before the cloud's origin is folded in.
struct Camera {
    int width = 1280;
    int height = 720;
    double fovyDegrees = 45.0;
    double nearPlane = 0.01;
    double farPlane = 100.0;
    glm::dmat4 view{1.0};
    /// > 0: an orthographic camera (a directional light's view) whose image is this many scene
    /// units tall; fovyDegrees is then unused. 0: a pinhole camera.
    double orthographicHeight = 0.0;
    /// Sub-pixel shift of the picture, in pixels (x right, y down): the temporal filter's jitter
    /// of the pipeline's camera. projection() and the shaders' viewPositionAt() include it; the
    /// viewer's picking ignores it (half a pixel at most).
    glm::dvec2 jitterPixels{0.0};
    /// Where the optical axis meets the picture, in pixels from its middle (x right, y down):
    /// a real sensor's principal point is rarely the exact centre. Shifts the picture as the
    /// jitter does (projection() and the shaders include both); kept by the temporal filter.
    glm::dvec2 principalOffsetPixels{0.0};
    /// The picture's whole sub-pixel and principal shift.
    glm::dvec2 pictureShiftPixels() const { return jitterPixels + principalOffsetPixels; }

    bool orthographic() const { return orthographicHeight > 0.0; }
    glm::dmat4 projection() const;
    /// Pinhole: pixels per unit of (view-space x or y) / depth, f = height / (2 tan(fovy / 2)).
    /// Orthographic: pixels per scene unit, height / orthographicHeight.
    double focalLengthPixels() const;
    /// Eye position in file coordinates.
    glm::dvec3 eye() const;
    /// view * translate(origin): maps cloud-relative positions straight to view space.
    glm::dmat4 viewFromCloud(const glm::dvec3& cloudOrigin) const {
        return view * translation(cloudOrigin);
    }

    static glm::dmat4 translation(const glm::dvec3& offset);
};

/// Pixels [x0, y0, x1, y1) (row 0 at the top) that hold every point of `bounds` a rasterizer
/// can draw with `camera`: the projected box plus a margin of 2 pixels for float rounding on the
/// GPU; the whole image when a corner lies on or behind the near plane (the box's projection is
/// then unbounded); empty (x1 <= x0) when `bounds` is empty or falls outside the image.
glm::ivec4 projectedPixelBounds(const Camera& camera, const Bounds& bounds);

/// The view-space direction through the centre of pixel (x, y) (row 0 at the top) of a
/// perspective camera, scaled to z = −1: the view-space point at linear depth d is d times it.
glm::dvec3 pixelCentreDirection(const Camera& camera, int x, int y);

/// Which way is up in a scan's coordinates. NegativeY: a depth camera's own frame (x right, y
/// down, z forward), as organised PCDs hold it.
enum class UpAxis { Y, Z, NegativeY };

/// The up axis `up` ("auto", "y", "z" or "-y") names for a scan read as `format` (LoadedScan's
/// and subscan.Cloud's: "las", "ply", ...): auto is Z for LAS-family files (airborne and
/// terrestrial LiDAR), Y otherwise (upAxisForScan also looks at an organised grid's camera).
/// Throws subscan::Error for any other name.
UpAxis upAxisFor(std::string_view up, std::string_view format);

/// The orbit's directions for an up axis: `up`, and from the orbited point towards the eye at
/// pitch 0, `front` (yaw 0) and `side` (yaw 90, the picture's right at yaw 0).
struct OrbitFrame {
    glm::dvec3 up;
    glm::dvec3 front;
    glm::dvec3 side;
};
OrbitFrame orbitFrame(UpAxis up);

/// How an orbit without a given distance frames the bounds: their bounding sphere fits the
/// narrower field of view with 5 % to spare, the same distance from every direction (what the
/// evaluation's and benchmark's views are defined by); or the box's corners, as seen from the
/// orbit's direction, reach 95 % of the half-field on the limiting side (what users see first:
/// the object fills the picture from any yaw and pitch).
enum class Framing { Sphere, Box };

/// A camera orbiting the middle of `bounds`: yaw turns around the up axis, pitch raises the eye.
/// Yaw 0, pitch 0 looks at the front: from +Z for Y-up data, from -Y for Z-up data (LiDAR), from
/// -Z (the depth camera's side) for -Y-up data (orbitFrame).
struct OrbitView {
    double yawDegrees = 30.0;
    double pitchDegrees = 20.0;
    /// Eye distance from the centre; by default from `framing`.
    std::optional<double> distance;
    UpAxis up = UpAxis::Y;
    /// The point orbited, file coordinates; by default the middle of the bounds.
    std::optional<glm::dvec3> center;
    Framing framing = Framing::Sphere;
    /// The box Framing::Box fills, when not the bounds themselves (framingBounds(), which
    /// leaves stray points out); the depth range still holds all of the bounds.
    std::optional<Bounds> framed;
};

/// The yaw and pitch (degrees, x and y) of the orbit whose direction from the centre towards
/// the eye is `towardsEye` (any length but zero): the inverse of orbitCamera's angles.
glm::dvec2 orbitAngles(const glm::dvec3& towardsEye, UpAxis up);

/// Frames `bounds` as `orbit` says; near and far hug the bounding sphere.
Camera orbitCamera(const Bounds& bounds, const OrbitView& orbit, int width, int height,
                   double fovyDegrees);

}  // namespace subscan
