#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/Camera.h"
#include "core/PointCloud.h"

namespace subscan {

/// What a point's drawn colour shows, as LiDAR viewers (Potree, CloudCompare) offer it:
/// - Rgb: the scan's own colour;
/// - Intensity: its intensity as grey, stretched between the 1st and 99th percentile
///   (scanners' ranges differ wildly);
/// - Height: a ramp (viridis: dark blue, teal, green, yellow) over the 1st to 99th percentile
///   of the coordinate along the up axis;
/// - Uniform: one light grey, for the shape alone;
/// - Auto: Rgb where the scan has colour; else Height for Z-up data (LiDAR: elevation is what
///   its users read first); else Uniform. Not Intensity: in the Stanford PLY scans (and most
///   object scans) it is the scanner's confidence, which speckles the surface.
enum class Coloring { Auto, Rgb, Intensity, Height, Uniform };

std::string toString(Coloring coloring);
/// Throws subscan::Error listing the choices.
Coloring parseColoring(std::string_view text);

/// The colour of each point under `coloring` (sRGB RGBA8, alpha from the scan's colour where it
/// has one, else opaque). Throws subscan::Error naming what is missing when the scan has no
/// colour (Rgb) or no intensity (Intensity).
std::vector<Rgba8> pointColors(const PointCloud& cloud, Coloring coloring, UpAxis up);

/// Intensity as grey (the Intensity colouring): sRGB levels 40 to 255.
std::vector<std::uint8_t> intensityGreys(const PointCloud& cloud);

}  // namespace subscan
