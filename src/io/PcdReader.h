#pragma once

#include <cstddef>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads a PCD file (versions 0.5-0.7; DATA ascii, binary or binary_compressed with LZF and
/// column-major fields) held in memory: x/y/z (float or double), packed rgb/rgba (float or
/// uint bits), normal_x/y/z, intensity. Organised clouds are flattened and NaN points (the PCD
/// way of saying "no measurement") dropped. Throws subscan::Error.
PointCloud readPcd(std::span<const std::byte> file, ReadContext& context);

}  // namespace subscan
