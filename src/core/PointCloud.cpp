#include "core/PointCloud.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

PointCloudBuilder::PointCloudBuilder(PointAttributes attributes, std::size_t expectedPoints,
                                     bool mapVertexIndices)
    : attributes_(attributes), mapVertexIndices_(mapVertexIndices) {
    cloud_.positions.reserve(expectedPoints);
    if (attributes_.color) {
        cloud_.colors.reserve(expectedPoints);
    }
    if (attributes_.normal) {
        cloud_.normals.reserve(expectedPoints);
    }
    if (attributes_.intensity) {
        cloud_.intensities.reserve(expectedPoints);
    }
    if (attributes_.classification) {
        cloud_.classifications.reserve(expectedPoints);
    }
}

void PointCloudBuilder::dropVertex() {
    if (mapVertexIndices_) {
        if (droppedPoints_ == 0) {
            vertexRemap_.resize(cloud_.positions.size());
            for (std::size_t i = 0; i < vertexRemap_.size(); ++i) {
                vertexRemap_[i] = static_cast<std::uint32_t>(i);
            }
        }
        vertexRemap_.push_back(kInvalidIndex);
    }
    ++droppedPoints_;
}

PointCloud PointCloudBuilder::finish(std::vector<std::string>& warnings) {
    const std::size_t total = validPoints() + droppedPoints_;
    if (validPoints() == 0) {
        if (total == 0) {
            throw Error("it contains no points");
        }
        throw Error(fmt::format(
            "all {} points have NaN or infinite coordinates (or ones beyond +-1e15)", total));
    }
    if (droppedPoints_ > 0) {
        warnings.push_back(fmt::format(
            "dropped {} of {} points with NaN or infinite coordinates (or ones beyond +-1e15)",
            droppedPoints_, total));
    }

    if (!vertexRemap_.empty()) {
        std::size_t kept = 0;
        for (const Triangle& t : cloud_.triangles) {
            const Triangle mapped{vertexRemap_[t[0]], vertexRemap_[t[1]], vertexRemap_[t[2]]};
            if (mapped[0] != kInvalidIndex && mapped[1] != kInvalidIndex &&
                mapped[2] != kInvalidIndex) {
                cloud_.triangles[kept++] = mapped;
            }
        }
        if (kept < cloud_.triangles.size()) {
            warnings.push_back(fmt::format("dropped {} faces that used a dropped vertex",
                                           cloud_.triangles.size() - kept));
        }
        cloud_.triangles.resize(kept);
    }

    // Re-centre on the middle of the bounds: floats then carry the least magnitude, hence the
    // finest steps. The shift is computed in double and applied once.
    const glm::dvec3 newOrigin = cloud_.bounds.center();
    const glm::dvec3 shift = cloud_.origin - newOrigin;
    if (keepResiduals_) {
        // The positions as without residuals; each residual gains what the shift rounds off.
        for (std::size_t i = 0; i < cloud_.positions.size(); ++i) {
            const glm::dvec3 shifted = glm::dvec3(cloud_.positions[i]) + shift;
            cloud_.positions[i] = glm::vec3(shifted);
            cloud_.positionResiduals[i] = glm::vec3(lostToFloat(shifted, cloud_.positions[i]) +
                                                    glm::dvec3(cloud_.positionResiduals[i]));
        }
    } else {
        for (glm::vec3& p : cloud_.positions) {
            p = glm::vec3(glm::dvec3(p) + shift);
        }
    }
    cloud_.origin = newOrigin;
    return std::move(cloud_);
}

double positionTolerance(const PointCloud& cloud) {
    if (cloud.coordinateStep > 0.0) {
        return 0.5 * cloud.coordinateStep;
    }
    if (cloud.doubleCoordinates) {
        return kDoubleCoordinateTolerance;
    }
    const glm::dvec3 extent = cloud.bounds.empty() ? glm::dvec3(0.0) : cloud.bounds.extent();
    return kFloatErrorFraction * std::max({extent.x, extent.y, extent.z});
}

void keepResidualsWhereNeeded(PointCloud& cloud) {
    if (!cloud.hasPositionResiduals()) {
        return;
    }
    const auto tolerance = static_cast<float>(positionTolerance(cloud));
    const bool needed = std::any_of(
        cloud.positionResiduals.begin(), cloud.positionResiduals.end(), [&](const glm::vec3& r) {
            return std::abs(r.x) > tolerance || std::abs(r.y) > tolerance ||
                   std::abs(r.z) > tolerance;
        });
    if (!needed) {
        cloud.positionResiduals.clear();
        cloud.positionResiduals.shrink_to_fit();
    }
}

Bounds framingBounds(const PointCloud& cloud) {
    constexpr std::size_t kFewest = 1000;
    constexpr std::size_t kSample = 200000;
    constexpr double kTail = 0.001;
    if (cloud.size() < kFewest) {
        return cloud.bounds;
    }
    const std::size_t stride = std::max<std::size_t>(1, cloud.size() / kSample);
    // One pass over the sample for all three axes: on 10 M points each sampled point is a
    // cache miss, which one pass per axis paid three times.
    std::array<std::vector<float>, 3> values;
    for (std::vector<float>& axisValues : values) {
        axisValues.reserve(cloud.size() / stride + 1);
    }
    for (std::size_t i = 0; i < cloud.size(); i += stride) {
        for (int axis = 0; axis < 3; ++axis) {
            values[static_cast<std::size_t>(axis)].push_back(cloud.positions[i][axis]);
        }
    }
    Bounds framed;
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<float>& axisValues = values[static_cast<std::size_t>(axis)];
        const auto low =
            static_cast<std::ptrdiff_t>(kTail * static_cast<double>(axisValues.size()));
        const auto high = static_cast<std::ptrdiff_t>(axisValues.size()) - 1 - low;
        std::nth_element(axisValues.begin(), axisValues.begin() + low, axisValues.end());
        framed.min[axis] = cloud.origin[axis] + axisValues[static_cast<std::size_t>(low)];
        std::nth_element(axisValues.begin(), axisValues.begin() + high, axisValues.end());
        framed.max[axis] = cloud.origin[axis] + axisValues[static_cast<std::size_t>(high)];
    }
    return framed;
}

}  // namespace subscan
