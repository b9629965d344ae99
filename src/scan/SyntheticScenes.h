#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "core/PointCloud.h"
#include "scan/Scene.h"
#include "scan/VirtualScanner.h"

namespace subscan {

/// A virtual scan of a built-in scene, from "NAME[?points=N][&noise=X]" (the part after
/// "synthetic:"), so every command works with no data file. The scan has exactly N points
/// (default 4000 for the sphere, 200000 for the others) with colours (the scene's albedo) and
/// true normals, from 8 views (see scanToPointCount). Range noise X is in metres, or in scan
/// spacings with an 'h' suffix ("0.1h"); the default is none for the sphere, whose points lie
/// exactly on the unit sphere, and 0.1 h for the others, about what a good structured-light
/// scanner shows. Throws subscan::Error for unknown names or parameters.
///
/// Besides the built-in scenes' names, two LiDAR sources scan the "outdoor" scene:
/// "outdoor-station" from one terrestrial station 1.5 m above the middle of the ground (equal
/// angular steps in azimuth and elevation, -60 to +90 degrees, 5 mm range noise), and
/// "outdoor-airborne" from one airborne strip 60 m up (scan lines across track over +-30
/// degrees, 3 cm range noise); both 200000 points by default, the step counts and line spacing
/// scaled to give them.
PointCloud makeSyntheticScene(std::string_view spec);

/// A synthetic source with what it was made from: the scene (the ground truth) and the
/// scanner's settings as used (ScannerSettings::mode says which kind of scan it is).
struct SyntheticSource {
    std::unique_ptr<Scene> scene;
    ScannerSettings scanner;
    PointCloud points;
};

/// As makeSyntheticScene, keeping the scene and the scanner settings.
SyntheticSource makeSyntheticSource(std::string_view spec);

/// The names makeSyntheticScene accepts besides builtInSceneNames(): the LiDAR sources.
std::span<const std::string_view> lidarSourceNames();

}  // namespace subscan
