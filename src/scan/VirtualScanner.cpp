#include "scan/VirtualScanner.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <numbers>
#include <string>
#include <thread>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/Srgb.h"
#include "scan/Marble.h"

namespace subscan {

namespace {

/// Scanner distance from the bounding sphere's centre, in bounding-sphere radii.
constexpr double kDistanceInRadii = 3.0;
constexpr double kRingElevationDegrees = 25.0;
constexpr int kFewestViewsWithTopView = 5;

/// SplitMix64 (Steele et al. 2014): a fast, well-mixed hash of a 64-bit value.
std::uint64_t splitMix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/// A standard normal draw that depends only on (seed, view, pixel): Box–Muller on two hashes.
double gaussianForRay(std::uint64_t seed, std::uint64_t view, std::uint64_t pixel) {
    const std::uint64_t first = splitMix64(splitMix64(splitMix64(seed) ^ view) ^ pixel);
    const std::uint64_t second = splitMix64(first);
    constexpr double kUnit = 1.0 / 9007199254740992.0;                   // 2^-53
    const double u1 = (static_cast<double>(first >> 11) + 1.0) * kUnit;  // (0, 1]: log is finite
    const double u2 = static_cast<double>(second >> 11) * kUnit;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

double boundingRadius(const Bounds& bounds) {
    const double radius = 0.5 * glm::length(bounds.extent());
    // A scene of one point still needs a camera that can see it.
    return radius > 0.0 ? radius : 1e-3;
}

/// The hits of one row of rays: an image row of one view, a station's vertical profile or an
/// airborne scan line.
using RowPoints = std::vector<PointRecord>;

struct ScanRows {
    std::vector<RowPoints> rows;  // view-major, then row
    std::size_t pointCount = 0;
};

/// Every ray of a scan: `rows` x `columns` of them, `rowsPerView` rows to a view (the noise of
/// each ray is seeded by its view and its index within the view).
struct RayGrid {
    std::size_t rows = 0;
    std::size_t columns = 0;
    std::size_t rowsPerView = 0;
    double maxDistance = 0.0;
    std::function<Ray(std::size_t row, std::size_t column)> ray;
};

RayGrid objectRays(const Bounds& bounds, const ScannerSettings& settings) {
    const auto resolution = static_cast<std::size_t>(settings.resolution);
    auto views =
        std::make_shared<const std::vector<ScannerView>>(scannerViews(bounds, settings.views));
    RayGrid grid;
    grid.rows = views->size() * resolution;
    grid.columns = resolution;
    grid.rowsPerView = resolution;
    grid.maxDistance = (kDistanceInRadii + 1.0) * boundingRadius(bounds);
    grid.ray = [views, resolution](std::size_t job, std::size_t column) {
        const ScannerView& view = (*views)[job / resolution];
        const std::size_t row = job % resolution;
        const double y =
            (1.0 - 2.0 * (static_cast<double>(row) + 0.5) / static_cast<double>(resolution)) *
            view.tanHalfFov;
        const double x =
            (2.0 * (static_cast<double>(column) + 0.5) / static_cast<double>(resolution) - 1.0) *
            view.tanHalfFov;
        return Ray{view.position, glm::normalize(view.forward + x * view.right + y * view.up)};
    };
    return grid;
}

/// The largest distance from `from` to a corner of `bounds`.
double farthestCorner(const Bounds& bounds, const glm::dvec3& from) {
    const glm::dvec3 far = glm::max(glm::abs(bounds.min - from), glm::abs(bounds.max - from));
    return glm::length(far);
}

/// Unit direction of azimuth `azimuth` (from +Z towards +X) and elevation `elevation`, radians.
glm::dvec3 stationDirection(double azimuth, double elevation) {
    return {std::sin(azimuth) * std::cos(elevation), std::sin(elevation),
            std::cos(azimuth) * std::cos(elevation)};
}

RayGrid stationRays(const Scene& scene, const StationSettings& station) {
    const glm::dvec3 origin = stationPosition(scene, station);
    const double azimuthStep = 2.0 * std::numbers::pi / station.azimuthSteps;
    const double lowest = glm::radians(station.minElevationDegrees);
    const double elevationStep =
        glm::radians(station.maxElevationDegrees - station.minElevationDegrees) /
        station.elevationSteps;
    RayGrid grid;
    grid.rows = static_cast<std::size_t>(station.azimuthSteps);
    grid.columns = static_cast<std::size_t>(station.elevationSteps);
    grid.rowsPerView = grid.rows;
    // Just past the farthest corner, so that a ray reaching the bounds' edge still hits.
    grid.maxDistance = station.maxRange > 0.0
                           ? station.maxRange
                           : 1.01 * farthestCorner(scene.bounds(), origin) + 1e-9;
    grid.ray = [=](std::size_t profile, std::size_t step) {
        return Ray{origin,
                   stationDirection(static_cast<double>(profile) * azimuthStep,
                                    lowest + (static_cast<double>(step) + 0.5) * elevationStep)};
    };
    return grid;
}

/// Along-track positions of an airborne strip's scan lines: `count` of them `spacing` apart,
/// centred on the bounds' extent along X.
struct FlightLines {
    double firstX = 0.0;
    double spacing = 0.0;
    std::size_t count = 0;
    double sensorY = 0.0;
    double trackZ = 0.0;
};

FlightLines flightLines(const Bounds& bounds, const AirborneSettings& airborne) {
    const double length = bounds.max.x - bounds.min.x;
    FlightLines lines;
    lines.count =
        static_cast<std::size_t>(std::max(1.0, std::floor(length / airborne.lineSpacing)));
    lines.spacing = airborne.lineSpacing;
    lines.firstX =
        bounds.center().x - 0.5 * (static_cast<double>(lines.count) - 1.0) * airborne.lineSpacing;
    lines.sensorY = bounds.min.y + airborne.altitude;
    lines.trackZ = bounds.center().z;
    return lines;
}

RayGrid airborneRays(const Bounds& bounds, const AirborneSettings& airborne) {
    const FlightLines lines = flightLines(bounds, airborne);
    if (lines.count > static_cast<std::size_t>(kMaxScannerAngularSteps)) {
        throw Error(fmt::format("the airborne line spacing {} m gives {} scan lines, more than {}",
                                airborne.lineSpacing, lines.count, kMaxScannerAngularSteps));
    }
    const double fieldOfView = glm::radians(airborne.fieldOfViewDegrees);
    const double angleStep = fieldOfView / airborne.pointsPerLine;
    RayGrid grid;
    grid.rows = lines.count;
    grid.columns = static_cast<std::size_t>(airborne.pointsPerLine);
    grid.rowsPerView = grid.rows;
    grid.maxDistance =
        1.01 * farthestCorner(bounds, glm::dvec3(bounds.min.x, lines.sensorY, lines.trackZ)) +
        glm::length(bounds.extent());
    grid.ray = [=](std::size_t line, std::size_t step) {
        const double angle = -0.5 * fieldOfView + (static_cast<double>(step) + 0.5) * angleStep;
        return Ray{glm::dvec3(lines.firstX + static_cast<double>(line) * lines.spacing,
                              lines.sensorY, lines.trackZ),
                   glm::dvec3(0.0, -std::cos(angle), std::sin(angle))};
    };
    return grid;
}

RayGrid scanRays(const Scene& scene, const ScannerSettings& settings) {
    switch (settings.mode) {
        case ScannerSettings::Mode::Station:
            return stationRays(scene, settings.station);
        case ScannerSettings::Mode::Airborne:
            return airborneRays(scene.bounds(), settings.airborne);
        case ScannerSettings::Mode::Object:
            break;
    }
    return objectRays(scene.bounds(), settings);
}

/// Casts every ray of the scan; rows are handed to threads one at a time and each ray's noise
/// is seeded by its own index, so neither the split nor the thread count changes the result.
ScanRows castRays(const Scene& scene, const ScannerSettings& settings, unsigned threads) {
    validate(settings);
    const Bounds bounds = scene.bounds();
    const RayGrid grid = scanRays(scene, settings);
    const double sigma = noiseSigma(bounds, settings);
    const MarbleAlbedo marble = MarbleAlbedo::forBounds(bounds);

    ScanRows result;
    result.rows.resize(grid.rows);
    auto scanRow = [&](std::size_t job) {
        const std::size_t viewIndex = job / grid.rowsPerView;
        const std::size_t row = job % grid.rowsPerView;
        RowPoints& points = result.rows[job];
        for (std::size_t column = 0; column < grid.columns; ++column) {
            const Ray ray = grid.ray(job, column);
            const std::optional<SurfaceHit> hit = scene.intersect(ray, grid.maxDistance);
            if (!hit) {
                continue;
            }
            const glm::dvec3 onSurface = ray.origin + hit->distance * ray.direction;
            PointRecord point;
            point.position = onSurface;
            if (sigma > 0.0) {
                const double offset =
                    sigma * gaussianForRay(settings.seed, viewIndex, row * grid.columns + column);
                point.position = ray.origin + (hit->distance + offset) * ray.direction;
            }
            if (settings.color == ScannerSettings::Color::Scene) {
                point.color = srgb8Color(hit->albedo);
            } else if (settings.color == ScannerSettings::Color::Marble) {
                point.color = srgb8Color(marble(onSurface));
            }
            point.normal = glm::vec3(hit->normal);
            points.push_back(point);
        }
    };

    const std::size_t jobs = result.rows.size();
    unsigned workers = threads != 0 ? threads : std::thread::hardware_concurrency();
    workers = static_cast<unsigned>(std::clamp<std::size_t>(workers, 1, jobs));
    std::atomic<std::size_t> nextJob{0};
    std::atomic<bool> failed{false};
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto work = [&] {
        try {
            for (std::size_t job = nextJob++; job < jobs && !failed; job = nextJob++) {
                scanRow(job);
            }
        } catch (...) {
            const std::lock_guard lock(failureMutex);
            if (!failure) {
                failure = std::current_exception();
            }
            failed = true;
        }
    };
    {
        std::vector<std::jthread> pool;
        for (unsigned i = 1; i < workers; ++i) {
            pool.emplace_back(work);
        }
        work();
    }
    if (failure) {
        std::rethrow_exception(failure);
    }
    for (const RowPoints& points : result.rows) {
        result.pointCount += points.size();
    }
    if (result.pointCount == 0) {
        throw Error(settings.mode == ScannerSettings::Mode::Object
                        ? fmt::format("the virtual scanner hit nothing: no ray of its {} views met "
                                      "the scene",
                                      settings.views)
                        : fmt::format("the virtual scanner hit nothing: no ray of its {} scan "
                                      "met the scene",
                                      scannerModeName(settings.mode)));
    }
    return result;
}

/// Builds the cloud from the rows, keeping `keep` of the `total` points evenly spread through
/// the scan's order: point floor(k * total / keep) for k = 0..keep-1 (all when keep == total),
/// stepped exactly in integers without forming k * total. Positions are rounded to float once,
/// relative to the centre of the exact bounds (PointCloudBuilder would round twice: relative to
/// the first point, then to the centre). Rows are freed as they are copied.
PointCloud buildCloud(ScanRows scan, const ScannerSettings& settings, std::size_t keep) {
    const std::size_t total = scan.pointCount;
    if (total > kMaxPoints) {
        throw Error(fmt::format("the scan has {} points, more than the {} subscan can hold", total,
                                kMaxPoints));
    }
    auto forEachKept = [&](bool release, auto&& visit) {
        const std::size_t step = total / keep, extra = total % keep;
        std::size_t index = 0, remainder = 0, kept = 0, rowStart = 0;
        for (RowPoints& points : scan.rows) {
            const std::size_t rowEnd = rowStart + points.size();
            for (; kept < keep && index < rowEnd; ++kept) {
                visit(points[index - rowStart]);
                index += step;
                remainder += extra;
                if (remainder >= keep) {
                    ++index;
                    remainder -= keep;
                }
            }
            rowStart = rowEnd;
            if (release) {
                RowPoints().swap(points);
            }
        }
    };
    PointCloud cloud;
    forEachKept(false, [&](const PointRecord& point) { cloud.bounds.add(point.position); });
    cloud.origin = cloud.bounds.center();
    const bool colors = settings.color != ScannerSettings::Color::None;
    cloud.positions.reserve(keep);
    cloud.colors.reserve(colors ? keep : 0);
    cloud.normals.reserve(settings.normals ? keep : 0);
    forEachKept(true, [&](const PointRecord& point) {
        cloud.positions.emplace_back(point.position - cloud.origin);
        if (colors) {
            cloud.colors.push_back(point.color);
        }
        if (settings.normals) {
            cloud.normals.push_back(point.normal);
        }
    });
    return cloud;
}

}  // namespace

void validate(const ScannerSettings& settings) {
    if (settings.views < 1 || settings.views > kMaxScannerViews) {
        throw Error(fmt::format("the scanner needs 1 to {} views, not {}", kMaxScannerViews,
                                settings.views));
    }
    if (settings.resolution < 1 || settings.resolution > kMaxScannerResolution) {
        throw Error(fmt::format("the scanner resolution must be 1 to {}, not {}",
                                kMaxScannerResolution, settings.resolution));
    }
    if (!(std::isfinite(settings.noise) && settings.noise >= 0.0)) {
        throw Error(fmt::format("the scanner noise must be a finite distance >= 0, not {}",
                                settings.noise));
    }
    if (settings.color != ScannerSettings::Color::None &&
        settings.color != ScannerSettings::Color::Scene &&
        settings.color != ScannerSettings::Color::Marble) {
        throw Error("the scanner colour mode is not none, scene or marble");
    }
    if (settings.mode != ScannerSettings::Mode::Object &&
        settings.mode != ScannerSettings::Mode::Station &&
        settings.mode != ScannerSettings::Mode::Airborne) {
        throw Error("the scanner mode is not object, station or airborne");
    }
    validate(settings.station);
    validate(settings.airborne);
}

void validate(const StationSettings& station) {
    if (station.position &&
        !(std::isfinite(station.position->x) && std::isfinite(station.position->y) &&
          std::isfinite(station.position->z))) {
        throw Error("the station position must be finite");
    }
    if (!(std::isfinite(station.instrumentHeight) && station.instrumentHeight >= 0.0)) {
        throw Error(
            fmt::format("the station's instrument height must be a finite distance >= 0, "
                        "not {}",
                        station.instrumentHeight));
    }
    if (station.azimuthSteps < 1 || station.azimuthSteps > kMaxScannerAngularSteps) {
        throw Error(fmt::format("the station needs 1 to {} azimuth steps, not {}",
                                kMaxScannerAngularSteps, station.azimuthSteps));
    }
    if (station.elevationSteps < 1 || station.elevationSteps > kMaxScannerAngularSteps) {
        throw Error(fmt::format("the station needs 1 to {} elevation steps, not {}",
                                kMaxScannerAngularSteps, station.elevationSteps));
    }
    if (!(station.minElevationDegrees >= -90.0 &&
          station.minElevationDegrees < station.maxElevationDegrees &&
          station.maxElevationDegrees <= 90.0)) {
        throw Error(
            fmt::format("the station's elevation range must satisfy -90 <= min < max <= "
                        "90 degrees, not {} to {}",
                        station.minElevationDegrees, station.maxElevationDegrees));
    }
    if (!(std::isfinite(station.maxRange) && station.maxRange >= 0.0)) {
        throw Error(
            fmt::format("the station's maximum range must be a finite distance >= 0 (0: "
                        "unlimited), not {}",
                        station.maxRange));
    }
}

void validate(const AirborneSettings& airborne) {
    if (!(std::isfinite(airborne.altitude) && airborne.altitude > 0.0)) {
        throw Error(fmt::format("the flight altitude must be a finite distance > 0, not {}",
                                airborne.altitude));
    }
    if (!(airborne.fieldOfViewDegrees > 0.0 && airborne.fieldOfViewDegrees < 180.0)) {
        throw Error(
            fmt::format("the airborne field of view must be between 0 and 180 degrees, "
                        "not {}",
                        airborne.fieldOfViewDegrees));
    }
    if (!(std::isfinite(airborne.lineSpacing) && airborne.lineSpacing > 0.0)) {
        throw Error(fmt::format("the airborne line spacing must be a finite distance > 0, not {}",
                                airborne.lineSpacing));
    }
    if (airborne.pointsPerLine < 1 || airborne.pointsPerLine > kMaxScannerAngularSteps) {
        throw Error(fmt::format("an airborne scan line needs 1 to {} points, not {}",
                                kMaxScannerAngularSteps, airborne.pointsPerLine));
    }
}

void to_json(nlohmann::json& json, const StationSettings& station) {
    json = {{"instrument_height", station.instrumentHeight},
            {"azimuth_steps", station.azimuthSteps},
            {"elevation_steps", station.elevationSteps},
            {"min_elevation_deg", station.minElevationDegrees},
            {"max_elevation_deg", station.maxElevationDegrees},
            {"max_range", station.maxRange}};
    if (station.position) {
        json["position"] = {station.position->x, station.position->y, station.position->z};
    }
}

void to_json(nlohmann::json& json, const AirborneSettings& airborne) {
    json = {{"altitude", airborne.altitude},
            {"field_of_view_deg", airborne.fieldOfViewDegrees},
            {"line_spacing", airborne.lineSpacing},
            {"points_per_line", airborne.pointsPerLine}};
}

void from_json(const nlohmann::json& json, StationSettings& station) {
    if (!json.is_object()) {
        throw Error("the scanner setting 'station' must be a JSON object");
    }
    StationSettings read;
    for (const auto& [key, value] : json.items()) {
        try {
            if (key == "position") {
                const auto xyz = value.get<std::array<double, 3>>();
                read.position = glm::dvec3(xyz[0], xyz[1], xyz[2]);
            } else if (key == "instrument_height") {
                read.instrumentHeight = value.get<double>();
            } else if (key == "azimuth_steps") {
                read.azimuthSteps = value.get<int>();
            } else if (key == "elevation_steps") {
                read.elevationSteps = value.get<int>();
            } else if (key == "min_elevation_deg") {
                read.minElevationDegrees = value.get<double>();
            } else if (key == "max_elevation_deg") {
                read.maxElevationDegrees = value.get<double>();
            } else if (key == "max_range") {
                read.maxRange = value.get<double>();
            } else {
                throw Error(fmt::format("'station.{}' is not a scanner setting", key));
            }
        } catch (const nlohmann::json::exception&) {
            throw Error(fmt::format("the scanner setting 'station.{}' has the wrong type ({})", key,
                                    value.type_name()));
        }
    }
    validate(read);
    station = read;
}

void from_json(const nlohmann::json& json, AirborneSettings& airborne) {
    if (!json.is_object()) {
        throw Error("the scanner setting 'airborne' must be a JSON object");
    }
    AirborneSettings read;
    for (const auto& [key, value] : json.items()) {
        try {
            if (key == "altitude") {
                read.altitude = value.get<double>();
            } else if (key == "field_of_view_deg") {
                read.fieldOfViewDegrees = value.get<double>();
            } else if (key == "line_spacing") {
                read.lineSpacing = value.get<double>();
            } else if (key == "points_per_line") {
                read.pointsPerLine = value.get<int>();
            } else {
                throw Error(fmt::format("'airborne.{}' is not a scanner setting", key));
            }
        } catch (const nlohmann::json::exception&) {
            throw Error(fmt::format("the scanner setting 'airborne.{}' has the wrong type ({})",
                                    key, value.type_name()));
        }
    }
    validate(read);
    airborne = read;
}

void to_json(nlohmann::json& json, const ScannerSettings& settings) {
    json = {{"mode", scannerModeName(settings.mode)},
            {"station", settings.station},
            {"airborne", settings.airborne},
            {"views", settings.views},
            {"resolution", settings.resolution},
            {"noise", settings.noise},
            {"noise_in_spacing_units", settings.noiseInSpacingUnits},
            {"color", colorModeName(settings.color)},
            {"normals", settings.normals},
            {"seed", settings.seed}};
}

void from_json(const nlohmann::json& json, ScannerSettings& settings) {
    if (!json.is_object()) {
        throw Error("scanner settings must be a JSON object");
    }
    ScannerSettings read;
    for (const auto& [key, value] : json.items()) {
        try {
            if (key == "mode") {
                const auto name = value.get<std::string>();
                const auto mode = parseScannerMode(name);
                if (!mode) {
                    throw Error(
                        fmt::format("the scanner setting 'mode' is '{}', not object, station or "
                                    "airborne",
                                    name));
                }
                read.mode = *mode;
            } else if (key == "station") {
                read.station = value.get<StationSettings>();
            } else if (key == "airborne") {
                read.airborne = value.get<AirborneSettings>();
            } else if (key == "views") {
                read.views = value.get<int>();
            } else if (key == "resolution") {
                read.resolution = value.get<int>();
            } else if (key == "noise") {
                read.noise = value.get<double>();
            } else if (key == "noise_in_spacing_units") {
                read.noiseInSpacingUnits = value.get<bool>();
            } else if (key == "color") {
                const auto name = value.get<std::string>();
                const auto color = parseColorMode(name);
                if (!color) {
                    throw Error(
                        fmt::format("the scanner setting 'color' is '{}', not none, "
                                    "scene or marble",
                                    name));
                }
                read.color = *color;
            } else if (key == "normals") {
                read.normals = value.get<bool>();
            } else if (key == "seed") {
                read.seed = value.get<std::uint64_t>();
            } else {
                throw Error(fmt::format("'{}' is not a scanner setting", key));
            }
        } catch (const nlohmann::json::exception&) {
            throw Error(fmt::format("the scanner setting '{}' has the wrong type ({})", key,
                                    value.type_name()));
        }
    }
    validate(read);
    settings = read;
}

std::optional<ScannerSettings::Mode> parseScannerMode(std::string_view name) {
    for (const auto mode : {ScannerSettings::Mode::Object, ScannerSettings::Mode::Station,
                            ScannerSettings::Mode::Airborne}) {
        if (name == scannerModeName(mode)) {
            return mode;
        }
    }
    return std::nullopt;
}

std::string_view scannerModeName(ScannerSettings::Mode mode) {
    switch (mode) {
        case ScannerSettings::Mode::Object:
            return "object";
        case ScannerSettings::Mode::Station:
            return "station";
        case ScannerSettings::Mode::Airborne:
            return "airborne";
    }
    return "unknown";
}

std::optional<ScannerSettings::Color> parseColorMode(std::string_view name) {
    for (const auto color : {ScannerSettings::Color::None, ScannerSettings::Color::Scene,
                             ScannerSettings::Color::Marble}) {
        if (name == colorModeName(color)) {
            return color;
        }
    }
    return std::nullopt;
}

std::string_view colorModeName(ScannerSettings::Color color) {
    switch (color) {
        case ScannerSettings::Color::None:
            return "none";
        case ScannerSettings::Color::Scene:
            return "scene";
        case ScannerSettings::Color::Marble:
            return "marble";
    }
    return "unknown";
}

std::optional<NoiseAmount> parseNoiseAmount(std::string_view text) {
    NoiseAmount amount;
    if (!text.empty() && text.back() == 'h') {
        amount.inSpacingUnits = true;
        text.remove_suffix(1);
    }
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), amount.value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        !std::isfinite(amount.value) || amount.value < 0.0) {
        return std::nullopt;
    }
    return amount;
}

std::vector<ScannerView> scannerViews(const Bounds& bounds, int views) {
    const glm::dvec3 centre = bounds.empty() ? glm::dvec3(0.0) : bounds.center();
    const double radius = boundingRadius(bounds);
    const double distance = kDistanceInRadii * radius;
    // The square image's inscribed circle is the bounding sphere's silhouette.
    const double tanHalfFov = radius / std::sqrt(distance * distance - radius * radius);

    const bool topView = views >= kFewestViewsWithTopView;
    const int ringViews = topView ? views - 1 : views;
    const double elevation = kRingElevationDegrees * std::numbers::pi / 180.0;
    std::vector<ScannerView> result;
    result.reserve(static_cast<std::size_t>(std::max(views, 0)));
    for (int k = 0; k < ringViews; ++k) {
        const double azimuth = 2.0 * std::numbers::pi * k / ringViews;
        const double tilt = k % 2 == 0 ? elevation : -elevation;
        const glm::dvec3 outward(std::sin(azimuth) * std::cos(tilt), std::sin(tilt),
                                 std::cos(azimuth) * std::cos(tilt));
        ScannerView view;
        view.position = centre + distance * outward;
        view.forward = -outward;
        view.right = glm::normalize(glm::cross(view.forward, glm::dvec3(0.0, 1.0, 0.0)));
        view.up = glm::cross(view.right, view.forward);
        view.tanHalfFov = tanHalfFov;
        result.push_back(view);
    }
    if (topView) {
        ScannerView view;
        view.position = centre + glm::dvec3(0.0, distance, 0.0);
        view.forward = {0.0, -1.0, 0.0};
        view.up = {0.0, 0.0, -1.0};  // the image's top is the back of the scene
        view.right = glm::cross(view.forward, view.up);
        view.tanHalfFov = tanHalfFov;
        result.push_back(view);
    }
    return result;
}

namespace {

/// `settings` with its station or airborne sampling `factor` times as dense along both
/// directions, or nullopt where that leaves the settings' limits.
std::optional<ScannerSettings> denser(const ScannerSettings& settings, double factor) {
    ScannerSettings scaled = settings;
    const auto steps = [factor](int count) {
        return std::max(1.0, std::round(static_cast<double>(count) * factor));
    };
    double largest = 0.0;
    if (settings.mode == ScannerSettings::Mode::Station) {
        const double azimuth = steps(settings.station.azimuthSteps);
        const double elevation = steps(settings.station.elevationSteps);
        largest = std::max(azimuth, elevation);
        scaled.station.azimuthSteps = static_cast<int>(std::min(azimuth, 1e9));
        scaled.station.elevationSteps = static_cast<int>(std::min(elevation, 1e9));
    } else {
        const double points = steps(settings.airborne.pointsPerLine);
        largest = points;
        scaled.airborne.pointsPerLine = static_cast<int>(std::min(points, 1e9));
        scaled.airborne.lineSpacing = settings.airborne.lineSpacing / factor;
    }
    if (largest > kMaxScannerAngularSteps) {
        return std::nullopt;
    }
    return scaled;
}

/// scanToPointCount for station and airborne scans: a coarse probe (about 64 rays along the
/// denser direction) predicts the density, as hits grow with its square; misses enlarge it.
PointCloud scanLiDARToPointCount(const Scene& scene, const ScannerSettings& settings,
                                 std::size_t count, unsigned threads) {
    validate(settings);
    constexpr double kProbeSteps = 64.0;
    constexpr double kMargin = 1.02;
    constexpr double kSmallestGrowth = 1.01;
    const double largest =
        settings.mode == ScannerSettings::Mode::Station
            ? std::max(settings.station.azimuthSteps, settings.station.elevationSteps)
            : settings.airborne.pointsPerLine;
    double factor = kProbeSteps / largest;
    auto scanAt = [&](double candidate) {
        const std::optional<ScannerSettings> scaled = denser(settings, candidate);
        if (!scaled) {
            throw Error(fmt::format("the virtual scanner cannot produce {} points in a {} scan",
                                    count, scannerModeName(settings.mode)));
        }
        return std::pair{castRays(scene, *scaled, threads), *scaled};
    };
    auto [scan, used] = scanAt(factor);
    while (scan.pointCount < count) {
        const double ratio =
            std::sqrt(static_cast<double>(count) / static_cast<double>(scan.pointCount));
        factor *= std::max(ratio * kMargin, kSmallestGrowth);
        std::tie(scan, used) = scanAt(factor);
    }
    return buildCloud(std::move(scan), used, count);
}

}  // namespace

double scanSpacing(const Bounds& bounds, const ScannerSettings& settings) {
    if (settings.mode == ScannerSettings::Mode::Station) {
        constexpr double kQuotedRange = 10.0;
        return kQuotedRange * 2.0 * std::numbers::pi / std::max(settings.station.azimuthSteps, 1);
    }
    if (settings.mode == ScannerSettings::Mode::Airborne) {
        const AirborneSettings& airborne = settings.airborne;
        const double acrossTrack = airborne.altitude * glm::radians(airborne.fieldOfViewDegrees) /
                                   std::max(airborne.pointsPerLine, 1);
        return std::sqrt(airborne.lineSpacing * acrossTrack);
    }
    const double radius = boundingRadius(bounds);
    const double distance = kDistanceInRadii * radius;
    const double tanHalfFov = radius / std::sqrt(distance * distance - radius * radius);
    return distance * 2.0 * tanHalfFov / std::max(settings.resolution, 1);
}

double noiseSigma(const Bounds& bounds, const ScannerSettings& settings) {
    return settings.noiseInSpacingUnits ? settings.noise * scanSpacing(bounds, settings)
                                        : settings.noise;
}

glm::dvec3 stationPosition(const Scene& scene, const StationSettings& settings) {
    if (settings.position) {
        return *settings.position;
    }
    const Bounds bounds = scene.bounds();
    const glm::dvec3 centre = bounds.center();
    const glm::dvec3 above(centre.x, bounds.max.y + 1.0, centre.z);
    const std::optional<SurfaceHit> ground =
        scene.intersect(Ray{above, glm::dvec3(0.0, -1.0, 0.0)}, bounds.max.y + 2.0 - bounds.min.y);
    const double groundY = ground ? above.y - ground->distance : bounds.min.y;
    return {centre.x, groundY + settings.instrumentHeight, centre.z};
}

namespace {

/// Whether nothing of `scene` lies between `sensor` and its surface point `p`. The tolerance
/// covers the hit's own error where the line meets the surface at a grazing angle.
bool visibleFrom(const Scene& scene, const glm::dvec3& sensor, const glm::dvec3& p) {
    const glm::dvec3 offset = p - sensor;
    const double distance = glm::length(offset);
    if (!(distance > 0.0)) {
        return true;
    }
    const double tolerance = 1e-5 * glm::length(scene.bounds().extent()) + 1e-4 * distance;
    const std::optional<SurfaceHit> hit =
        scene.intersect(Ray{sensor, offset / distance}, distance - tolerance);
    return !hit;
}

}  // namespace

bool scannerCanSample(const Scene& scene, const ScannerSettings& settings, const glm::dvec3& p,
                      const glm::dvec3& normal) {
    switch (settings.mode) {
        case ScannerSettings::Mode::Object:
            return true;
        case ScannerSettings::Mode::Station: {
            const StationSettings& station = settings.station;
            const glm::dvec3 sensor = stationPosition(scene, station);
            const glm::dvec3 offset = p - sensor;
            const double range = glm::length(offset);
            const double elevation =
                glm::degrees(std::atan2(offset.y, std::hypot(offset.x, offset.z)));
            if (station.maxRange > 0.0 && range > station.maxRange) {
                return false;
            }
            if (elevation < station.minElevationDegrees ||
                elevation > station.maxElevationDegrees) {
                return false;
            }
            return visibleFrom(scene, sensor, p);
        }
        case ScannerSettings::Mode::Airborne: {
            const FlightLines lines = flightLines(scene.bounds(), settings.airborne);
            const double lastX =
                lines.firstX + static_cast<double>(lines.count - 1) * lines.spacing;
            if (p.x < lines.firstX - 0.5 * lines.spacing || p.x > lastX + 0.5 * lines.spacing) {
                return false;
            }
            const glm::dvec3 sensor(p.x, lines.sensorY, lines.trackZ);
            const double below = sensor.y - p.y;
            const double angle = std::atan2(std::abs(p.z - sensor.z), below);
            if (below <= 0.0 || angle > 0.5 * glm::radians(settings.airborne.fieldOfViewDegrees)) {
                return false;
            }
            // Scan lines cross the surface lineSpacing / sqrt(1 - n.x^2) apart along it.
            constexpr double kLeastCrossing = 0.1;
            if (std::sqrt(std::max(0.0, 1.0 - normal.x * normal.x)) < kLeastCrossing) {
                return false;
            }
            return visibleFrom(scene, sensor, p);
        }
    }
    return true;
}

PointCloud scanScene(const Scene& scene, const ScannerSettings& settings, unsigned threads) {
    ScanRows scan = castRays(scene, settings, threads);
    const std::size_t total = scan.pointCount;
    return buildCloud(std::move(scan), settings, total);
}

PointCloud scanToPointCount(const Scene& scene, ScannerSettings settings, std::size_t count,
                            unsigned threads) {
    if (count == 0 || count > kMaxPoints) {
        throw Error(fmt::format("a scan cannot have {} points", count));
    }
    if (settings.mode != ScannerSettings::Mode::Object) {
        return scanLiDARToPointCount(scene, settings, count, threads);
    }
    // A coarse probe measures how much of the image the scene covers; hits grow with the square
    // of the resolution, so the probe predicts the resolution, and misses enlarge it.
    constexpr int kProbeResolution = 16;
    constexpr double kMargin = 1.02;
    settings.resolution = kProbeResolution;
    ScanRows scan = castRays(scene, settings, threads);
    bool probing = true;
    while (probing || scan.pointCount < count) {
        const double ratio =
            std::sqrt(static_cast<double>(count) / static_cast<double>(scan.pointCount));
        const double predicted = std::ceil(settings.resolution * ratio * kMargin);
        const int next =
            probing ? static_cast<int>(std::max(1.0, predicted))
                    : static_cast<int>(std::max<double>(settings.resolution + 1, predicted));
        if (next > kMaxScannerResolution) {
            throw Error(fmt::format("the virtual scanner cannot produce {} points with {} views",
                                    count, settings.views));
        }
        settings.resolution = next;
        scan = castRays(scene, settings, threads);
        probing = false;
    }
    return buildCloud(std::move(scan), settings, count);
}

}  // namespace subscan
