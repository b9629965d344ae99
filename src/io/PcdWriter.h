#pragma once

#include <filesystem>

#include <glm/vec3.hpp>
#include <optional>

#include "core/PointCloud.h"

namespace subscan {

/// Writes `cloud` as a PCD 0.7 file with DATA binary, atomically (see writeFileAtomically), one
/// row (WIDTH = points, HEIGHT 1) seen from `viewpoint` (VIEWPOINT; PCL's default, the origin,
/// where none is given): fields x y z (F 4, or F 8 where float
/// would lose precision, see needsDoubleCoordinates), then, each when the cloud has it, rgb
/// (U 4, packed 0x00RRGGBB as PCL packs it), intensity (F 4) and normal_x normal_y normal_z
/// (F 4). Alpha and faces are not written. Throws subscan::Error naming the file when it cannot
/// be written.
void writePcd(const std::filesystem::path& path, const PointCloud& cloud,
              std::optional<glm::dvec3> viewpoint = std::nullopt);

}  // namespace subscan
