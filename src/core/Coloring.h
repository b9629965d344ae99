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
/// - Classification: the ASPRS LAS class code's colour (classificationColor);
/// - Auto: Rgb where the scan has colour; else Height for Z-up data (LiDAR: elevation is what
///   its users read first); else Uniform. Not Intensity: in the Stanford PLY scans (and most
///   object scans) it is the scanner's confidence, which speckles the surface.
enum class Coloring { Auto, Rgb, Intensity, Height, Uniform, Classification };

std::string toString(Coloring coloring);
/// Throws subscan::Error listing the choices.
Coloring parseColoring(std::string_view text);
/// Every colouring's name, in the order of the enum, for command-line checks and help texts.
std::vector<std::string> coloringNames();

/// ASPRS LAS 1.4 R15 standard classes (table 17) as sRGB colours in the spirit of Potree and
/// CloudCompare: greys for never classified (0) and unclassified (1), brown ground (2), greens
/// from light to dark for low, medium and high vegetation (3-5), orange buildings (6), magenta
/// low noise (7), yellow key-points (8), blue water (9), purple rail (10), dark slate road
/// surface (11), pale yellow overlap (12), pink wire guard (13), cyan wire conductor (14), dark
/// red transmission tower (15), teal wire connector (16), tan bridge deck (17), red high noise
/// (18); every code above 18 (reserved or user-defined) a neutral grey.
Rgba8 classificationColor(std::uint8_t code);

/// The colour of each point under `coloring` (sRGB RGBA8, alpha from the scan's colour where it
/// has one, else opaque). Throws subscan::Error naming what is missing when the scan has no
/// colour (Rgb), no intensity (Intensity) or no classification (Classification).
std::vector<Rgba8> pointColors(const PointCloud& cloud, Coloring coloring, UpAxis up);

/// Intensity as grey (the Intensity colouring): sRGB levels 40 to 255.
std::vector<std::uint8_t> intensityGreys(const PointCloud& cloud);

}  // namespace subscan
