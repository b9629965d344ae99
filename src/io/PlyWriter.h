#pragma once

#include <filesystem>

#include "core/PointCloud.h"

namespace subscan {

/// Writes `cloud` as a binary_little_endian PLY, atomically (see writeFileAtomically): vertex
/// x y z, then red green blue (uchar, sRGB as stored; alpha too unless every point is opaque),
/// nx ny nz (float), intensity (float), each when the cloud has it, and the triangles as a
/// `face` element with `vertex_indices` lists. Coordinates are written as float, or as double
/// where float would lose precision (needsDoubleCoordinates, e.g. UTM coordinates). Throws
/// subscan::Error naming the file when it cannot be written.
void writePly(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace subscan
