#pragma once

#include <cstddef>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads an ASCII OFF mesh held in memory (Geomview's Object File Format, as Princeton's shape
/// benchmark and many mesh tools write it): the keyword [ST][C][N][4]OFF (optional), the vertex,
/// face and edge counts, one vertex per line (x y z [w] [normal] [colour] [s t]), then one
/// polygon per line (n i1 .. in [colour]), fanned into triangles so the mesh can serve as
/// ground truth. A vertex colour is 0..1 when any of its channels has a decimal point or an
/// exponent, else 0..255. '#' starts a comment.
/// BINARY and nOFF files are refused. Throws subscan::Error.
PointCloud readOff(std::span<const std::byte> file, ReadContext& context);

}  // namespace subscan
