#pragma once

#include <cstddef>

#include "core/PointCloud.h"

namespace subscan {

/// The point spacing h of DESIGN.md §4: the median distance from a point to its nearest
/// (non-coincident) neighbour, in scene units. Large clouds are estimated on `maxSamples`
/// evenly spread query points (each still searched against the whole cloud). Returns 0 for
/// clouds with fewer than two distinct points.
double estimateSpacing(const PointCloud& cloud, std::size_t maxSamples = 20000);

}  // namespace subscan
