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

/// Where a terrestrial LiDAR station stands and how it turns (ScannerSettings::Mode::Station).
/// Rays leave the station in equal angular steps: azimuth over the full circle, elevation over
/// [minElevationDegrees, maxElevationDegrees] (Y is up, elevation 0 is horizontal), so the
/// spacing of the points grows with their range and far ground is sampled in rings.
struct StationSettings {
    /// Unset: instrumentHeight above the first surface straight below the bounds' centre.
    std::optional<glm::dvec3> position;
    double instrumentHeight = 1.5;
    int azimuthSteps = 1800;   // rays per full turn (0.2 degrees apart)
    int elevationSteps = 750;  // rays per vertical profile, at the centres of equal steps
    double minElevationDegrees = -60.0;
    double maxElevationDegrees = 90.0;
    double maxRange = 0.0;  // metres; 0: unlimited

    friend bool operator==(const StationSettings&, const StationSettings&) = default;
};

/// A straight flight over the scene (ScannerSettings::Mode::Airborne): along +X through the
/// bounds' centre at `altitude` above the bounds' bottom, from one end of the bounds to the
/// other. Each scan line sweeps a fan of rays in the vertical plane across the track, in equal
/// angular steps over the field of view centred on nadir.
struct AirborneSettings {
    double altitude = 60.0;            // metres above the bottom of the scene's bounds
    double fieldOfViewDegrees = 60.0;  // the whole sweep across track (+-30 degrees)
    double lineSpacing = 0.25;         // metres between scan lines along the track
    int pointsPerLine = 400;           // rays per scan line

    friend bool operator==(const AirborneSettings&, const AirborneSettings&) = default;
};

/// How the virtual scanner samples a scene.
struct ScannerSettings {
    enum class Mode {
        Object,    // a structured-light scanner's views around the object (see scannerViews)
        Station,   // one terrestrial LiDAR station (see StationSettings)
        Airborne,  // one airborne LiDAR strip (see AirborneSettings)
    };
    enum class Color {
        None,    // no colours
        Scene,   // the scene's albedo, encoded as 8-bit sRGB
        Marble,  // procedural marble evaluated at each hit, whatever the scene's own colours
    };

    Mode mode = Mode::Object;
    int views = 8;                     // scanner positions (see scannerViews)
    int resolution = 512;              // rays per side of each view's square image
    double noise = 0.0;                // standard deviation of the range noise along each ray
    bool noiseInSpacingUnits = false;  // noise is in units of the scan spacing h, not metres
    Color color = Color::Scene;
    bool normals = false;  // store each hit's true surface normal
    std::uint64_t seed = 1;
    StationSettings station;    // used in Mode::Station
    AirborneSettings airborne;  // used in Mode::Airborne

    friend bool operator==(const ScannerSettings&, const ScannerSettings&) = default;
};

inline constexpr int kMaxScannerViews = 1000;
inline constexpr int kMaxScannerResolution = 16384;
inline constexpr int kMaxScannerAngularSteps = 100000;

/// Throws subscan::Error (one sentence naming the setting) unless every value is in range.
void validate(const ScannerSettings& settings);
void validate(const StationSettings& station);
void validate(const AirborneSettings& airborne);

/// JSON keys: mode ("object", "station", "airborne"), views, resolution, noise,
/// noise_in_spacing_units, color ("none", "scene", "marble"), normals, seed, station (an object:
/// position [x, y, z], instrument_height, azimuth_steps, elevation_steps, min_elevation_deg,
/// max_elevation_deg, max_range) and airborne (altitude, field_of_view_deg, line_spacing,
/// points_per_line). from_json starts from the defaults, so any key may be left out; unknown
/// keys and bad values throw subscan::Error.
void to_json(nlohmann::json& json, const ScannerSettings& settings);
void from_json(const nlohmann::json& json, ScannerSettings& settings);
void to_json(nlohmann::json& json, const StationSettings& station);
void from_json(const nlohmann::json& json, StationSettings& station);
void to_json(nlohmann::json& json, const AirborneSettings& airborne);
void from_json(const nlohmann::json& json, AirborneSettings& airborne);

/// "object", "station" or "airborne"; nullopt for anything else.
std::optional<ScannerSettings::Mode> parseScannerMode(std::string_view name);
std::string_view scannerModeName(ScannerSettings::Mode mode);

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

/// The scan spacing h the noise is measured in. Object mode: the footprint of one pixel at the
/// bounding sphere's centre, distance x pixel angle (2 tan(half fov) / resolution); surfaces
/// facing the scanner are sampled about this densely in each view, overlapping views denser.
/// Station: the spacing of neighbouring rays at 10 m range (10 m x the azimuth step), the range
/// LiDAR makers quote it at. Airborne: the geometric mean of the line spacing and the spacing
/// across track at nadir on the bounds' bottom (altitude x angular step).
double scanSpacing(const Bounds& bounds, const ScannerSettings& settings);

/// The range noise's standard deviation in metres.
double noiseSigma(const Bounds& bounds, const ScannerSettings& settings);

/// Where the station of `settings` stands in `scene` (see StationSettings::position).
glm::dvec3 stationPosition(const Scene& scene, const StationSettings& settings);

/// Whether a scan with `settings` samples the surface point `p` of `scene` (unit outward
/// `normal`) at the density its settings give: object mode, always; station mode, when p is in
/// the station's elevation range and maximum range and nothing lies between the station and p;
/// airborne mode, when p lies under the flight line's extent, within the field of view of the
/// scan line through it, nothing lies between that line's sensor position and p, and the
/// surface is not within 6 degrees of parallel to the vertical scan planes (a wall facing along
/// the track, which scan lines cross more than 10 line spacings apart, or never). The
/// evaluation counts coverage only over such points (a station cannot see the backs of
/// buildings).
bool scannerCanSample(const Scene& scene, const ScannerSettings& settings, const glm::dvec3& p,
                      const glm::dvec3& normal);

/// Scans the scene. Object mode, from every view: a resolution x resolution grid of rays through
/// pixel centres, the first hit of each ray (so self-occlusion is real), moved along its ray by
/// Gaussian noise; points are ordered by view, then image row, then column. Station mode: one
/// vertical profile per azimuth step, in azimuth order, each from the lowest elevation up.
/// Airborne mode: one scan line after the other along the track, each from -Z to +Z. The first
/// hit of each ray is a point, moved along its ray by the noise. The result depends
/// only on the scene and the settings (noise is seeded per ray), never on `threads`
/// (0: one per hardware thread). Throws subscan::Error for bad settings or when nothing is hit.
PointCloud scanScene(const Scene& scene, const ScannerSettings& settings, unsigned threads = 0);

/// A scan of exactly `count` points: the sampling density is chosen so that at least `count`
/// points come out (object mode: the resolution, settings.resolution is ignored; station: both
/// step counts scaled alike; airborne: the points per line and the line spacing scaled alike), then
/// `count` of them, evenly spread through the scan's order, are kept. Deterministic like scanScene.
PointCloud scanToPointCount(const Scene& scene, ScannerSettings settings, std::size_t count,
                            unsigned threads = 0);

}  // namespace subscan
