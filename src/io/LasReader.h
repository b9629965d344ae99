#pragma once

#include <cstddef>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads an uncompressed LAS file (versions 1.0-1.4, point formats 0-10) held in memory:
/// coordinates with scale and offset applied in double, intensity, and RGB where the point
/// format has it (16-bit reduced to 8-bit; files that store 8-bit values in the 16-bit fields are
/// detected). Compressed LAS (LAZ, COPC) is rejected with a clear error. Throws subscan::Error.
PointCloud readLas(std::span<const std::byte> file, ReadContext& context);

}  // namespace subscan
