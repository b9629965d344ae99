#pragma once

#include <filesystem>

#include "core/PointCloud.h"

namespace subscan {

/// Writes `cloud` as a text list of points, atomically (see writeFileAtomically). The first line
/// names the columns with PDAL's dimension names, which subscan's XyzReader (and PDAL's text
/// reader) map back to them: X Y Z, then Red Green Blue (0-255), Intensity and NormalX NormalY
/// NormalZ, each only when the cloud has it. Then one line per point, values separated by a
/// space, each number in the shortest form that reads back as the same double (coordinates) or
/// float (the rest). Alpha and faces are not written. Throws subscan::Error naming the file when
/// it cannot be written.
void writeXyz(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace subscan
