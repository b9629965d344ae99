#pragma once

#include <cstddef>
#include <vector>

#include "core/PointCloud.h"

namespace subscan {

/// The point spacing h of DESIGN.md §4: the median distance from a point to its nearest
/// non-coincident neighbour, in scene units. Large clouds are estimated on `maxSamples` query
/// points, point i·n/maxSamples for i < maxSamples, each still searched exactly against the
/// whole cloud. Returns 0 for clouds with fewer than two distinct points.
double estimateSpacing(const PointCloud& cloud, std::size_t maxSamples = 20000);

/// The distance from each query point of estimateSpacing to its nearest non-coincident point
/// in the whole cloud (looking past at least seven copies of the query), +infinity where there
/// is none.
std::vector<float> sampledNearestDistances(const PointCloud& cloud, std::size_t maxSamples = 20000);

/// estimateSpacing's h and the sampledNearestDistances it is the median of, from one search
/// (what deciding on the local spacing needs too).
struct SpacingSample {
    double h = 0.0;
    std::vector<float> nearest;
};
SpacingSample sampleSpacing(const PointCloud& cloud, std::size_t maxSamples = 20000);

}  // namespace subscan
