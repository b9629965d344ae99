#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Error.h"
#include "io/PlyWriter.h"
#include "io/TextParsing.h"
#include "scan/Scene.h"
#include "scan/VirtualScanner.h"

namespace subscan::cli {

namespace {

constexpr std::string_view kSyntheticPrefix = "synthetic:";

struct ScanOptions {
    std::string source;
    std::string output;
    ScannerSettings settings;
    std::string noise = "0";
    std::string color = "auto";
    std::string mode = "object";
    std::vector<double> stationPosition;
    bool json = false;
};

/// The scene to scan: a built-in one, or the triangles of a mesh file.
struct ScanSource {
    std::unique_ptr<Scene> scene;
    bool hasColors = false;
};

ScanSource openSource(const ScanOptions& options) {
    const std::string_view source = options.source;
    if (source.starts_with(kSyntheticPrefix)) {
        const std::string_view name = source.substr(kSyntheticPrefix.size());
        if (name.find('?') != std::string_view::npos) {
            throw Error(fmt::format(
                "{}: 'subscan scan' takes a bare scene name; set the scan with --resolution, "
                "--noise and the other options instead of ?parameters",
                source));
        }
        try {
            return {makeBuiltInScene(name), true};
        } catch (const Error& error) {
            throw Error(fmt::format("{}: {}", source, error.what()));
        }
    }
    if (sameFile(options.source, options.output)) {
        throw Error(
            fmt::format("{}: refusing to write the scan over its own input file; "
                        "choose another output path",
                        options.output));
    }
    const LoadedScan mesh = loadScanForCommand(source);
    if (mesh.cloud.triangles.empty()) {
        throw Error(
            fmt::format("{}: it has no faces, but 'subscan scan' needs a triangle mesh "
                        "(e.g. a PLY with a face element)",
                        source));
    }
    return {makeMeshScene(mesh.cloud, AlbedoSource::VertexColors), mesh.cloud.hasColors()};
}

int runScan(ScanOptions options) {
    const ScanSource source = openSource(options);
    ScannerSettings& settings = options.settings;
    settings.mode = parseScannerMode(options.mode).value();  // checked by the parser
    if (!options.stationPosition.empty()) {
        settings.station.position = glm::dvec3(
            options.stationPosition[0], options.stationPosition[1], options.stationPosition[2]);
    }
    validate(settings);
    const NoiseAmount noise = parseNoiseAmount(options.noise).value();  // checked by the parser
    settings.noise = noise.value;
    settings.noiseInSpacingUnits = noise.inSpacingUnits;
    if (options.color == "auto") {
        // Plain grey from a mesh without colours would only pretend to be data.
        settings.color =
            source.hasColors ? ScannerSettings::Color::Scene : ScannerSettings::Color::None;
    } else {
        settings.color = parseColorMode(options.color).value();  // checked by the parser
    }

    const auto start = std::chrono::steady_clock::now();
    const PointCloud cloud = scanScene(*source.scene, settings);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    writePly(options.output, cloud);

    const double sigma = noiseSigma(source.scene->bounds(), settings);
    if (options.json) {
        nlohmann::json summary = {{"points", cloud.size()},
                                  {"views", settings.views},
                                  {"resolution", settings.resolution},
                                  {"noise_m", sigma},
                                  {"seconds", seconds}};
        if (settings.mode != ScannerSettings::Mode::Object) {
            summary["mode"] = scannerModeName(settings.mode);
            summary["spacing_m"] = scanSpacing(source.scene->bounds(), settings);
        }
        fmt::print("{}\n", summary.dump(2));
        return 0;
    }
    if (settings.mode == ScannerSettings::Mode::Station) {
        const glm::dvec3 station = stationPosition(*source.scene, settings.station);
        fmt::print(
            "{}: {} points scanned from {} by a station at ({:.3g}, {:.3g}, {:.3g}) in {} x {} "
            "angular steps, noise {:.3g} m, {:.2f} s\n",
            options.output, cloud.size(), options.source, station.x, station.y, station.z,
            settings.station.azimuthSteps, settings.station.elevationSteps, sigma, seconds);
        return 0;
    }
    if (settings.mode == ScannerSettings::Mode::Airborne) {
        fmt::print(
            "{}: {} points scanned from {} by an airborne strip {} m up, lines {} m apart of {} "
            "points, noise {:.3g} m, {:.2f} s\n",
            options.output, cloud.size(), options.source, settings.airborne.altitude,
            settings.airborne.lineSpacing, settings.airborne.pointsPerLine, sigma, seconds);
        return 0;
    }
    fmt::print("{}: {} points scanned from {} in {} views at {}x{}, noise {:.3g} m, {:.2f} s\n",
               options.output, cloud.size(), options.source, settings.views, settings.resolution,
               settings.resolution, sigma, seconds);
    return 0;
}

}  // namespace

Command addScanCommand(CLI::App& parent) {
    auto options = std::make_shared<ScanOptions>();
    CLI::App* scan = parent.add_subcommand(
        "scan", "Virtual structured-light scanner: a realistic scan of a mesh or built-in scene");
    scan->add_option("source", options->source,
                     fmt::format("Mesh with faces (e.g. PLY), or synthetic:NAME ({})",
                                 fmt::join(builtInSceneNames(), ", ")))
        ->required();
    scan->add_option("-o,--output", options->output, "Output PLY file")
        ->required()
        ->check(
            [](const std::string& path) -> std::string {
                // Other extensions were written as PLY all the same, which other tools refuse.
                return asciiLowercase(std::filesystem::path(path).extension().string()) == ".ply"
                           ? std::string()
                           : fmt::format(
                                 "'{}' is not a .ply file: scan writes "
                                 "PLY (convert writes other formats)",
                                 path);
            },
            "FILE.ply");
    scan->add_option("--views", options->settings.views,
                     "Scanner positions: a ring around the object, alternately 25 degrees above "
                     "and below it, plus one from the top when 5 or more")
        ->check(CLI::Range(1, kMaxScannerViews))
        ->capture_default_str();
    scan->add_option("--resolution", options->settings.resolution,
                     "Rays per side of each view's square image")
        ->check(CLI::Range(1, kMaxScannerResolution))
        ->capture_default_str();
    scan->add_option("--noise", options->noise,
                     "Range noise (standard deviation along each ray) in metres, or with an h "
                     "suffix in scan spacings (pixel footprint at the object's centre), e.g. "
                     "0.1h")
        ->check(
            [](const std::string& text) -> std::string {
                return parseNoiseAmount(text)
                           ? std::string()
                           : "must be a distance >= 0 in metres, or in scan spacings with an h "
                             "suffix (e.g. 0.0002 or 0.1h)";
            },
            "DISTANCE[h]")
        ->capture_default_str();
    scan->add_option("--color", options->color,
                     "Point colours: the scene's (scene), procedural marble, none, or auto "
                     "(scene's when it has colours)")
        ->check(CLI::IsMember({"auto", "none", "scene", "marble"}))
        ->capture_default_str();
    scan->add_option("--mode", options->mode,
                     "object: structured-light views around the object; station: one "
                     "terrestrial LiDAR station (equal angular steps); airborne: one airborne "
                     "LiDAR strip along +X")
        ->check(CLI::IsMember({"object", "station", "airborne"}))
        ->capture_default_str();
    StationSettings& station = options->settings.station;
    scan->add_option("--station", options->stationPosition,
                     "Station position X Y Z or X,Y,Z (as render's --sensor); default: the "
                     "instrument height above the first surface below the scene's middle")
        ->expected(3)
        ->delimiter(',');
    scan->add_option("--instrument-height", station.instrumentHeight,
                     "Station height above the ground below it (metres)")
        ->capture_default_str();
    scan->add_option("--azimuth-steps", station.azimuthSteps, "Station rays per full turn")
        ->check(CLI::Range(1, kMaxScannerAngularSteps))
        ->capture_default_str();
    scan->add_option("--elevation-steps", station.elevationSteps,
                     "Station rays per vertical profile, over the elevation range")
        ->check(CLI::Range(1, kMaxScannerAngularSteps))
        ->capture_default_str();
    scan->add_option("--min-elevation", station.minElevationDegrees,
                     "Station's lowest elevation (degrees, 0 horizontal)")
        ->capture_default_str();
    scan->add_option("--max-elevation", station.maxElevationDegrees,
                     "Station's highest elevation (degrees, 90 straight up)")
        ->capture_default_str();
    scan->add_option("--max-range", station.maxRange, "Station's maximum range (metres; 0: none)")
        ->capture_default_str();
    AirborneSettings& airborne = options->settings.airborne;
    scan->add_option("--altitude", airborne.altitude,
                     "Airborne: flight height above the bottom of the scene (metres)")
        ->capture_default_str();
    scan->add_option("--field-of-view", airborne.fieldOfViewDegrees,
                     "Airborne: the whole sweep across track (degrees), centred on nadir")
        ->capture_default_str();
    scan->add_option("--line-spacing", airborne.lineSpacing,
                     "Airborne: distance between scan lines along the track (metres)")
        ->capture_default_str();
    scan->add_option("--points-per-line", airborne.pointsPerLine, "Airborne: rays per scan line")
        ->check(CLI::Range(1, kMaxScannerAngularSteps))
        ->capture_default_str();
    scan->add_flag("--normals", options->settings.normals, "Store each point's true normal");
    scan->add_option("--seed", options->settings.seed, "Seed of the noise")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    scan->add_flag("--json", options->json,
                   "Machine-readable summary: points, views, resolution, noise_m and seconds "
                   "(scanning only, without loading and writing)");
    return {scan, [options] { return runScan(*options); }};
}

}  // namespace subscan::cli
