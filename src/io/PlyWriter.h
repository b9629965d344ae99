#pragma once

#include <filesystem>

#include "core/PointCloud.h"

namespace subscan {

/// Writes `cloud` as a binary_little_endian PLY, atomically (see writeFileAtomically): vertex
/// x y z, then red green blue (uchar, sRGB as stored; alpha too unless every point is opaque),
/// nx ny nz (float), intensity (float), each when the cloud has it, and the triangles as a
/// `face` element with `vertex_indices` lists. Coordinates are written as float unless float's
/// rounding of the file coordinates would exceed 1e-6 of the cloud's extent (e.g. UTM
/// coordinates), then as double. Throws subscan::Error naming the file when it cannot be written.
void writePly(const std::filesystem::path& path, const PointCloud& cloud);

/// Whether writePly stores this cloud's coordinates as double.
bool plyNeedsDoubleCoordinates(const PointCloud& cloud);

}  // namespace subscan
