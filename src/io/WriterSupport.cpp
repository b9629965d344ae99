#include "io/WriterSupport.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace subscan {

namespace {

/// How far rounding a coordinate of this magnitude to float moves it at most: half a step.
double floatRounding(double magnitude) {
    const auto value = static_cast<float>(magnitude);
    return 0.5 *
           static_cast<double>(std::nextafter(value, std::numeric_limits<float>::max()) - value);
}

double largestComponent(const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 magnitude = glm::max(glm::abs(a), glm::abs(b));
    return std::max({magnitude.x, magnitude.y, magnitude.z});
}

}  // namespace

bool needsDoubleCoordinates(const PointCloud& cloud) {
    if (cloud.size() == 0 || cloud.bounds.empty()) {
        return false;
    }
    const double written = floatRounding(largestComponent(cloud.bounds.min, cloud.bounds.max));
    const glm::dvec3 extent = cloud.bounds.extent();
    const double size = std::max({extent.x, extent.y, extent.z});
    // Residuals give back what the floats relative to the centre lost; without them, what
    // memory already lost cannot be kept by doubles either.
    const double inMemory = cloud.hasPositionResiduals()
                                ? 0.0
                                : floatRounding(largestComponent(cloud.bounds.min - cloud.origin,
                                                                 cloud.bounds.max - cloud.origin));
    // On a file's grid, less than half a step still rounds back to the stored integer; doubles
    // from the file are kept as far as memory kept them.
    const double allowed =
        cloud.coordinateStep > 0.0 ? std::max(0.5 * cloud.coordinateStep, inMemory)
        : cloud.doubleCoordinates  ? inMemory
                                   : std::max(kFloatErrorFraction * size, inMemory);
    return written > allowed;
}

bool hasTranslucentColors(const PointCloud& cloud) {
    return std::any_of(cloud.colors.begin(), cloud.colors.end(),
                       [](const Rgba8& color) { return color.a != 255; });
}

}  // namespace subscan
