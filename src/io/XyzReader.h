#pragma once

#include <cstddef>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads a text list of points held in memory (XYZ, PTS, TXT, CSV): one point per line, values
/// separated by whitespace, commas or semicolons; `x y z`, `x y z i`, `x y z r g b`,
/// `x y z i r g b` (PTS, after its count line) and a few more layouts; leading header lines are
/// skipped (and used to name the columns when they can). Throws subscan::Error.
PointCloud readXyz(std::span<const std::byte> file, ReadContext& context);

/// True when the start of `file` reads as lines of numbers, for files without a telling extension.
bool looksLikePointText(std::span<const std::byte> file);

}  // namespace subscan
