#pragma once

#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/Camera.h"
#include "core/PointCloud.h"
#include "render/RenderSettings.h"

namespace subscan {

/// The camera of a reconstruction at 1/`divisor` of `output`'s pixels per side: ceil(W/d) x
/// ceil(H/d) pixels, the same eye, the focal length divided by d, centred on the output's
/// centre (so the reduced image may reach half an output pixel past an odd-sized output).
Camera reducedCamera(const Camera& output, int divisor);

/// Where an output position (pixel units, pixel centres at .5) falls in the reduced image of
/// `reducedCamera(output, divisor)`, in the same units.
glm::dvec2 reducedPosition(const Camera& output, const Camera& reduced, int divisor,
                           const glm::dvec2& outputPosition);

/// Picks the divisor of RasterSettings::resolution for a frame. Auto reconstructs at half
/// resolution when the cloud's points are sparse on screen, four or more pixels apart for all
/// but the densest tenth of the points in view (a close-up): there most pixels are gaps that
/// pull-push only interpolates, and the half-resolution grid still receives every point on
/// its own texel. The estimate projects a fixed, evenly strided sample of the cloud, so it costs
/// microseconds and gives the same answer for the same camera.
class ResolutionChooser {
  public:
    explicit ResolutionChooser(const PointCloud& cloud);

    /// Takes the sample's entries of the cloud's local spacing (estimateLocalSpacing).
    void setLocalSpacing(const std::vector<glm::vec4>& spacing);

    /// 1 or 2. `spacing` is the point spacing h in scene units; with `useLocalSpacing` (and a
    /// local spacing given) each sample point's own spacing on screen, as the rasterizer
    /// projects it, stands in for h.
    int divisor(Resolution resolution, const Camera& camera, const glm::dvec3& cloudOrigin,
                double spacing, bool useLocalSpacing) const;

  private:
    std::vector<glm::vec3> sample_;  // cloud-relative positions
    std::vector<std::size_t> sampleIndices_;
    std::vector<glm::vec4> localSpacing_;  // per sample point, empty without
};

}  // namespace subscan
