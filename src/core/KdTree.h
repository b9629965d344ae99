#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>
#include <nanoflann.hpp>

namespace subscan {

/// nanoflann's view of a position array, for the k-d trees of the spacing estimates.
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

}  // namespace subscan
