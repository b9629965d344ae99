#pragma once

#include <string_view>

#include "core/PointCloud.h"

namespace subscan {

/// A virtual scan of a built-in scene, from "NAME[?points=N][&noise=X]" (the part after
/// "synthetic:"), so every command works with no data file. The scan has exactly N points
/// (default 4000 for the sphere, 200000 for the others) with colours (the scene's albedo) and
/// true normals, from 8 views (see scanToPointCount). Range noise X is in metres, or in scan
/// spacings with an 'h' suffix ("0.1h"); the default is none for the sphere, whose points lie
/// exactly on the unit sphere, and 0.1 h for the others, about what a good structured-light
/// scanner shows. Throws subscan::Error for unknown names or parameters.
PointCloud makeSyntheticScene(std::string_view spec);

}  // namespace subscan
