#pragma once

#include <string_view>

#include "core/PointCloud.h"

namespace subscan {

/// Builds a built-in scene from "NAME[?points=N]" (the part after "synthetic:"), so every
/// command works with no data file. Throws subscan::Error for unknown names or parameters.
PointCloud makeSyntheticScene(std::string_view spec);

}  // namespace subscan
