#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Camera.h"
#include "core/PointCloud.h"

namespace subscan {

/// Where the scanner or camera stood, as the file records it: a PCD VIEWPOINT, an E57 scan's
/// pose, or a position the user gives (`--sensor X,Y,Z`).
struct SensorPose {
    glm::dvec3 position{0.0};  // file coordinates
    std::string source;        // e.g. "the PCD VIEWPOINT", for messages
};

/// An organised cloud (a depth camera's image): the grid and, for each point kept, its cell
/// (row-major, row 0 at the top as the sensor delivered it).
struct OrganisedGrid {
    int width = 0;
    int height = 0;
    std::vector<std::uint32_t> cellOfPoint;

    bool empty() const { return width <= 0 || height <= 1 || cellOfPoint.empty(); }
};

/// A pinhole camera fitted to an organised cloud: the projection (direct linear transform over
/// every point, normalised as Hartley and Zisserman advise) that sends each point to the middle
/// of its grid cell.
struct PinholeFit {
    Camera camera;                      // the grid's size, fovy from fy, near/far around the points
    double focalX = 0.0, focalY = 0.0;  // pixels
    glm::dvec2 principalPoint{0.0};     // pixels from the top-left corner
    double rmsErrorPixels = 0.0;        // of the points' projections against their cells' middles
};

/// Throws subscan::Error when the points do not determine a camera in front of them (fewer than
/// 6 points, all on one plane, or a projection that is no camera).
PinholeFit fitPinhole(const PointCloud& cloud, const OrganisedGrid& grid);

/// The largest RMS reprojection error (pixels) at which a grid is taken for a pinhole camera's
/// image; a scanner's organised grid (rows of angles, not a pinhole) misses by far more.
inline constexpr double kPinholeToleranceRmsPixels = 1.0;

/// upAxisFor's axis, except that `auto` for an organised cloud whose grid is a pinhole image
/// takes -Y where its camera's picture points up along -Y (within 45 degrees): a depth
/// camera's own frame, which the Y-up default showed upside down and from behind.
UpAxis upAxisForScan(std::string_view up, std::string_view format, const PointCloud& cloud,
                     const OrganisedGrid& grid);

/// The view from `sensor`: towards the middle of the points' framing box (level, towards its
/// azimuth, from a sensor inside the points' bounds: a station amid its scene), `up` kept
/// upright (or the orbit's front direction when looking straight along it), near and far around
/// the points. Throws subscan::Error when the sensor lies more than 20 box diagonals from the
/// points (a default or unrelated pose: the points would be a speck).
Camera sensorCamera(const PointCloud& cloud, const SensorPose& sensor, UpAxis up, int width,
                    int height, double fovyDegrees);

/// The view from where the scan was taken: an organised cloud's own camera, fitted to its grid
/// (at the grid's size, or at `width` x `height` with the same field of view when `sizeGiven`);
/// else, or when the grid is no pinhole image (a warning says so), sensorCamera() from `pose`.
/// Throws subscan::Error when there is neither.
Camera viewFromSensor(const PointCloud& cloud, const OrganisedGrid& grid,
                      const std::optional<SensorPose>& pose, UpAxis up, int width, int height,
                      bool sizeGiven, double fovyDegrees, std::vector<std::string>& warnings);

}  // namespace subscan
