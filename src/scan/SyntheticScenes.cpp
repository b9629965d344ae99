#include "scan/SyntheticScenes.h"

#include <array>
#include <charconv>
#include <string>

#include <fmt/format.h>

#include "core/Error.h"
#include "scan/Scene.h"
#include "scan/VirtualScanner.h"

namespace subscan {

namespace {

constexpr std::size_t kMaxSyntheticPoints = 100'000'000;

constexpr std::string_view kLidarScene = "outdoor";
constexpr std::string_view kStationSource = "outdoor-station";
constexpr std::string_view kAirborneSource = "outdoor-airborne";
constexpr std::array<std::string_view, 2> kLidarSourceNames{kStationSource, kAirborneSource};
/// Range noise of a good terrestrial scanner (a few mm at tens of metres) and of airborne
/// LiDAR (a few cm), in metres: unlike a structured-light scanner's, it does not scale with the
/// spacing.
constexpr double kStationNoiseMetres = 0.005;
constexpr double kAirborneNoiseMetres = 0.03;

struct SyntheticRequest {
    std::size_t points = 0;  // 0: the scene's default
    std::optional<NoiseAmount> noise;
};

std::size_t parsePointCount(std::string_view value) {
    std::size_t points = 0;
    const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), points);
    if (ec != std::errc() || end != value.data() + value.size() || points == 0 ||
        points > kMaxSyntheticPoints) {
        throw Error(fmt::format("points={} is not a point count between 1 and {}", value,
                                kMaxSyntheticPoints));
    }
    return points;
}

/// Parses "key=value&key=value" after the '?'.
SyntheticRequest parseParameters(std::string_view parameters) {
    SyntheticRequest request;
    while (!parameters.empty()) {
        const std::size_t ampersand = parameters.find('&');
        const std::string_view parameter = parameters.substr(0, ampersand);
        parameters = ampersand == std::string_view::npos ? std::string_view()
                                                         : parameters.substr(ampersand + 1);
        const std::size_t equals = parameter.find('=');
        const std::string_view key = parameter.substr(0, equals);
        const std::string_view value =
            equals == std::string_view::npos ? std::string_view() : parameter.substr(equals + 1);
        if (equals != std::string_view::npos && key == "points") {
            request.points = parsePointCount(value);
        } else if (equals != std::string_view::npos && key == "noise") {
            request.noise = parseNoiseAmount(value);
            if (!request.noise) {
                throw Error(fmt::format(
                    "noise={} is not a distance >= 0 in metres or scan spacings (e.g. 0.0002 or "
                    "0.1h)",
                    value));
            }
        } else {
            throw Error(
                fmt::format("unknown synthetic scene parameter '{}' (expected points=N or noise=X)",
                            parameter));
        }
    }
    return request;
}

}  // namespace

PointCloud makeSyntheticScene(std::string_view spec) {
    return makeSyntheticSource(spec).points;
}

std::span<const std::string_view> lidarSourceNames() {
    return kLidarSourceNames;
}

SyntheticSource makeSyntheticSource(std::string_view spec) {
    const std::size_t query = spec.find('?');
    const std::string_view name = spec.substr(0, query);
    const SyntheticRequest request = parseParameters(
        query == std::string_view::npos ? std::string_view() : spec.substr(query + 1));

    SyntheticSource source;
    ScannerSettings& settings = source.scanner;
    settings.color = ScannerSettings::Color::Scene;
    settings.normals = true;
    NoiseAmount noise;
    std::size_t defaultPoints = 200'000;
    if (name == kStationSource || name == kAirborneSource) {
        source.scene = makeBuiltInScene(kLidarScene);
        const bool station = name == kStationSource;
        settings.mode = station ? ScannerSettings::Mode::Station : ScannerSettings::Mode::Airborne;
        noise = {.value = station ? kStationNoiseMetres : kAirborneNoiseMetres,
                 .inSpacingUnits = false};
        if (station) {
            // Fixed once here, so the evaluation looks from the very spot that was scanned.
            settings.station.position = stationPosition(*source.scene, settings.station);
        }
    } else {
        try {
            source.scene = makeBuiltInScene(name);
        } catch (const Error& error) {
            throw Error(fmt::format("{}, or the LiDAR sources {}", error.what(),
                                    fmt::join(kLidarSourceNames, ", ")));
        }
        const bool sphere = name == "sphere";
        noise = {.value = sphere ? 0.0 : 0.1, .inSpacingUnits = true};
        defaultPoints = sphere ? 4000 : 200'000;
    }
    noise = request.noise.value_or(noise);
    settings.noise = noise.value;
    settings.noiseInSpacingUnits = noise.inSpacingUnits;
    const std::size_t points = request.points != 0 ? request.points : defaultPoints;
    source.points = scanToPointCount(*source.scene, settings, points);
    return source;
}

}  // namespace subscan
