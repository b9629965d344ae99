#include "core/Spacing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <nanoflann.hpp>

namespace subscan {

namespace {

struct PositionsAdaptor {
    const std::vector<glm::vec3>& positions;

    std::size_t kdtree_get_point_count() const { return positions.size(); }
    float kdtree_get_pt(std::size_t index, std::size_t axis) const {
        return positions[index][static_cast<glm::length_t>(axis)];
    }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox&) const {
        return false;
    }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PositionsAdaptor>,
                                        PositionsAdaptor, 3, std::uint32_t>;

}  // namespace

double estimateSpacing(const PointCloud& cloud, std::size_t maxSamples) {
    const std::size_t count = cloud.size();
    if (count < 2 || maxSamples == 0) {
        return 0.0;
    }
    const PositionsAdaptor adaptor{cloud.positions};
    const KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));

    // Scans often repeat points (overlapping range images, quantised coordinates), so look a
    // few neighbours deep for the first one at a non-zero distance.
    constexpr std::size_t kNeighbours = 8;
    const std::size_t samples = std::min(count, maxSamples);
    std::vector<float> nearest;
    nearest.reserve(samples);
    std::array<std::uint32_t, kNeighbours> indices{};
    std::array<float, kNeighbours> squaredDistances{};
    for (std::size_t s = 0; s < samples; ++s) {
        const std::size_t index = s * count / samples;
        const glm::vec3& query = cloud.positions[index];
        const std::size_t found =
            tree.knnSearch(&query.x, kNeighbours, indices.data(), squaredDistances.data());
        for (std::size_t k = 0; k < found; ++k) {
            if (squaredDistances[k] > 0.0f) {
                nearest.push_back(squaredDistances[k]);
                break;
            }
        }
    }
    if (nearest.empty()) {
        return 0.0;
    }
    const auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
    std::nth_element(nearest.begin(), middle, nearest.end());
    return std::sqrt(static_cast<double>(*middle));
}

}  // namespace subscan
