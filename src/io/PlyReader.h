#pragma once

#include <cstddef>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads a PLY file (ascii, binary_little_endian, binary_big_endian) held in memory: the
/// `vertex` element's x/y/z (any scalar type), colour (red/green/blue[/alpha], diffuse_*; uchar,
/// ushort or float), nx/ny/nz and intensity/scalar_intensity; `face` lists as triangles
/// (polygons fanned). Other elements and properties are skipped. Throws subscan::Error.
PointCloud readPly(std::span<const std::byte> file, ReadContext& context);

}  // namespace subscan
