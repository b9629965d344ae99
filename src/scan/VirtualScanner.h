#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/PointCloud.h"
#include "scan/Scene.h"

namespace subscan {

/// How the virtual structured-light scanner samples a scene.
struct ScannerSettings {
    enum class Color {
        None,    // no colours
        Scene,   // the scene's albedo, encoded as 8-bit sRGB
        Marble,  // procedural marble evaluated at each hit, whatever the scene's own colours
    };

    int views = 8;                     // scanner positions (see scannerViews)
    int resolution = 512;              // rays per side of each view's square image
    double noise = 0.0;                // standard deviation of the range noise along each ray
    bool noiseInSpacingUnits = false;  // noise is in units of the scan spacing h, not metres
    Color color = Color::Scene;
    bool normals = false;  // store each hit's true surface normal
    std::uint64_t seed = 1;

    friend bool operator==(const ScannerSettings&, const ScannerSettings&) = default;
};

inline constexpr int kMaxScannerViews = 1000;
inline constexpr int kMaxScannerResolution = 16384;

/// Throws subscan::Error (one sentence naming the setting) unless every value is in range.
void validate(const ScannerSettings& settings);

/// JSON keys: views, resolution, noise, noise_in_spacing_units, color ("none", "scene",
/// "marble"), normals, seed. from_json starts from the defaults, so any key may be left out;
/// unknown keys and bad values throw subscan::Error.
void to_json(nlohmann::json& json, const ScannerSettings& settings);
void from_json(const nlohmann::json& json, ScannerSettings& settings);

/// "none", "scene" or "marble"; nullopt for anything else.
std::optional<ScannerSettings::Color> parseColorMode(std::string_view name);
std::string_view colorModeName(ScannerSettings::Color color);

/// A noise amount as users write it: metres ("0.0002") or scan spacings ("0.1h").
struct NoiseAmount {
    double value = 0.0;
    bool inSpacingUnits = false;
};
/// nullopt unless `text` is a finite non-negative number, optionally followed by 'h'.
std::optional<NoiseAmount> parseNoiseAmount(std::string_view text);

/// One scanner position: a pinhole camera whose square image just contains the scene's
/// bounding sphere.
struct ScannerView {
    glm::dvec3 position{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};  // unit, towards the bounding sphere's centre
    glm::dvec3 right{1.0, 0.0, 0.0};     // unit, image x
    glm::dvec3 up{0.0, 1.0, 0.0};        // unit, image y
    double tanHalfFov = 0.0;             // of the square image's half side
};

/// Where the scanner stands for a scene with `bounds`. Every view is 3 bounding-sphere radii
/// from the sphere's centre (a field of view of about 39 degrees, like a desktop
/// structured-light scanner) and looks at the centre. With 5 or more views one looks straight
/// down from above (Y is up) and the others stand on a ring around the Y axis, evenly spaced in
/// azimuth starting in front (+Z), alternately 25 degrees above and below the centre; with fewer
/// views all are on that ring.
std::vector<ScannerView> scannerViews(const Bounds& bounds, int views);

/// The scan spacing h the noise is measured in: the footprint of one pixel at the bounding
/// sphere's centre, distance x pixel angle (2 tan(half fov) / resolution). Surfaces facing the
/// scanner are sampled about this densely in each view; overlapping views sample denser.
double scanSpacing(const Bounds& bounds, const ScannerSettings& settings);

/// The range noise's standard deviation in metres.
double noiseSigma(const Bounds& bounds, const ScannerSettings& settings);

/// Scans the scene from every view: a resolution x resolution grid of rays through pixel
/// centres, the first hit of each ray (so self-occlusion is real), moved along its ray by
/// Gaussian noise. Points are ordered by view, then image row, then column. The result depends
/// only on the scene and the settings (noise is seeded per ray), never on `threads`
/// (0: one per hardware thread). Throws subscan::Error for bad settings or when nothing is hit.
PointCloud scanScene(const Scene& scene, const ScannerSettings& settings, unsigned threads = 0);

/// A scan of exactly `count` points: the resolution is chosen (settings.resolution is ignored)
/// so that at least `count` points come out, then `count` of them, evenly spread through the
/// scan's order, are kept. Deterministic like scanScene.
PointCloud scanToPointCount(const Scene& scene, ScannerSettings settings, std::size_t count,
                            unsigned threads = 0);

}  // namespace subscan
