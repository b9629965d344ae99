#include "io/WriterSupport.h"

#include <algorithm>
#include <limits>

namespace subscan {

namespace {

/// Relative rounding error of float coordinates we accept, as a fraction of the extent.
constexpr double kFloatErrorFraction = 1e-6;

}  // namespace

bool needsDoubleCoordinates(const PointCloud& cloud) {
    if (cloud.size() == 0 || cloud.bounds.empty()) {
        return false;
    }
    const glm::dvec3 magnitude = glm::max(glm::abs(cloud.bounds.min), glm::abs(cloud.bounds.max));
    const double largest = std::max({magnitude.x, magnitude.y, magnitude.z});
    const glm::dvec3 extent = cloud.bounds.extent();
    const double size = std::max({extent.x, extent.y, extent.z});
    // Rounding to float moves a coordinate by up to half a float step at the largest magnitude.
    const double floatError =
        0.5 * largest * static_cast<double>(std::numeric_limits<float>::epsilon());
    return floatError > kFloatErrorFraction * size;
}

bool hasTranslucentColors(const PointCloud& cloud) {
    return std::any_of(cloud.colors.begin(), cloud.colors.end(),
                       [](const Rgba8& color) { return color.a != 255; });
}

}  // namespace subscan
