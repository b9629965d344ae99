#include "render/ReducedResolution.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/trigonometric.hpp>

namespace subscan {

namespace {

/// Enough points for a stable tenth percentile, few enough to project every frame unnoticed.
constexpr std::size_t kSampleSize = 4096;
/// Fewer sample points in view than this say little about spacing: keep full resolution.
constexpr std::size_t kFewestInView = 64;
/// The share of points in view allowed closer together than kSparseSpacingPixels.
constexpr double kDenseShare = 0.1;
/// Points this far apart leave gaps of a texel or more even at half resolution. Measured against
/// ground truth (bench/README.md), 2 pixels lost up to 7 % coverage on the sculpture at
/// 1024x1024: the silhouette loses about a texel, and half-resolution texels are larger.
constexpr double kSparseSpacingPixels = 4.0;

}  // namespace

Camera reducedCamera(const Camera& output, int divisor) {
    Camera reduced = output;
    reduced.width = (output.width + divisor - 1) / divisor;
    reduced.height = (output.height + divisor - 1) / divisor;
    // The reduced rows span divisor * height' >= height output rows at the same pixel angle.
    const double halfTangent = std::tan(0.5 * glm::radians(output.fovyDegrees)) *
                               static_cast<double>(divisor * reduced.height) /
                               static_cast<double>(output.height);
    reduced.fovyDegrees = glm::degrees(2.0 * std::atan(halfTangent));
    reduced.jitterPixels = output.jitterPixels / static_cast<double>(divisor);
    reduced.principalOffsetPixels = output.principalOffsetPixels / static_cast<double>(divisor);
    return reduced;
}

glm::dvec2 reducedPosition(const Camera& output, const Camera& reduced, int divisor,
                           const glm::dvec2& outputPosition) {
    const glm::dvec2 outputCentre(0.5 * output.width, 0.5 * output.height);
    const glm::dvec2 reducedCentre(0.5 * reduced.width, 0.5 * reduced.height);
    return reducedCentre + (outputPosition - outputCentre) / static_cast<double>(divisor);
}

ResolutionChooser::ResolutionChooser(const PointCloud& cloud) {
    const std::size_t count = std::min(cloud.size(), kSampleSize);
    sample_.reserve(count);
    sampleIndices_.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        sampleIndices_.push_back(i * cloud.size() / count);
        sample_.push_back(cloud.positions[sampleIndices_.back()]);
    }
}

void ResolutionChooser::setLocalSpacing(const std::vector<glm::vec4>& spacing) {
    localSpacing_.clear();
    for (const std::size_t index : sampleIndices_) {
        localSpacing_.push_back(spacing.at(index));
    }
}

int ResolutionChooser::divisor(Resolution resolution, const Camera& camera,
                               const glm::dvec3& cloudOrigin, double spacing,
                               bool useLocalSpacing) const {
    if (resolution != Resolution::Auto) {
        return resolution == Resolution::Half ? 2 : 1;
    }
    const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloudOrigin);
    const double focal = camera.focalLengthPixels();
    const double halfWidth = 0.5 * camera.width;
    const double halfHeight = 0.5 * camera.height;
    std::vector<double> spacingPixels;
    spacingPixels.reserve(sample_.size());
    const bool local = useLocalSpacing && !localSpacing_.empty();
    for (std::size_t s = 0; s < sample_.size(); ++s) {
        const glm::dvec4 view = viewFromCloud * glm::dvec4(glm::dvec3(sample_[s]), 1.0);
        const double depth = -view.z;
        if (!(depth > camera.nearPlane && depth < camera.farPlane) ||
            std::abs(view.x) * focal > halfWidth * depth ||
            std::abs(view.y) * focal > halfHeight * depth) {
            continue;
        }
        double ratio = 1.0;
        if (local) {
            // RasterizePoints.comp's spacingRatio, for a pinhole camera.
            const glm::dvec3 across = glm::dmat3(viewFromCloud) * glm::dvec3(localSpacing_[s]);
            const glm::dvec2 moved = glm::dvec2(across) + glm::dvec2(view) * (across.z / depth);
            ratio = std::max<double>(localSpacing_[s].w, glm::length(moved));
        }
        spacingPixels.push_back(focal * spacing * ratio / depth);
    }
    if (spacingPixels.size() < kFewestInView) {
        return 1;
    }
    const auto dense =
        spacingPixels.begin() + static_cast<std::ptrdiff_t>(kDenseShare * spacingPixels.size());
    std::nth_element(spacingPixels.begin(), dense, spacingPixels.end());
    return *dense >= kSparseSpacingPixels ? 2 : 1;
}

}  // namespace subscan
