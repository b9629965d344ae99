#include "app/cli/CommandSupport.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>
#include <system_error>
#include <utility>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include "app/ProgressBar.h"
#include "core/Error.h"
#include "core/SensorView.h"
#include "lod/NodeSelection.h"
#include "sss/MaterialLibrary.h"

namespace subscan::cli {

CLI::Validator finiteNumber() {
    return CLI::Validator(
        [](std::string& text) {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            return end != text.c_str() && !std::isfinite(value)
                       ? fmt::format("'{}' is not a finite number", text)
                       : std::string();
        },
        "FINITE");
}

CLI::Validator parsedBy(std::function<void(const std::string&)> parse) {
    return CLI::Validator(
        [parse = std::move(parse)](std::string& text) {
            try {
                parse(text);
                return std::string();
            } catch (const Error& error) {
                return std::string(error.what());
            }
        },
        "");
}

void requireOutputFolder(const std::filesystem::path& output) {
    const std::filesystem::path folder = output.parent_path();
    std::error_code error;
    if (!output.empty() && !folder.empty() && !std::filesystem::is_directory(folder, error)) {
        throw Error(
            fmt::format("{}: its folder {} does not exist", output.string(), folder.string()));
    }
}

void removeEarlierOutput(const std::filesystem::path& path, std::string_view what) {
    std::error_code error;
    std::filesystem::remove(path, error);
    if (error) {
        throw Error(fmt::format("{}: cannot remove {}: {}", path.string(), what, error.message()));
    }
}

LoadedScan loadScanForCommand(std::string_view source, bool keepFilePrecision) {
    constexpr std::uintmax_t kProgressBarBytes = 50u << 20;
    std::error_code ignored;
    const std::uintmax_t bytes = std::filesystem::file_size(std::string(source), ignored);
    ProgressBar bar("loading", !ignored && bytes > kProgressBarBytes);
    LoadedScan scan = loadScan(
        source, [&](double fraction) { bar.update(fraction); }, keepFilePrecision);
    for (const std::string& warning : scan.warnings) {
        fmt::print(stderr, "subscan: warning: {}: {}\n", source, warning);
    }
    return scan;
}

void StreamingOptions::add(CLI::App& command) {
    command
        .add_option("--lod", lod,
                    "Levels of detail: auto (stream COPC files and EPT datasets, load the rest "
                    "whole), on (stream, or refuse), off (load every file whole)")
        ->check(CLI::IsMember({"auto", "on", "off"}));
    command
        .add_option("--point-budget", pointBudget,
                    fmt::format("Most points a streamed view loads (default {} on software "
                                "rendering, {} on a GPU)",
                                lod::kSoftwarePointBudget, lod::kHardwarePointBudget))
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40));
}

void StreamingOptions::apply(StreamingSettings& settings) const {
    if (lod) {
        settings.lod = lod::parseLodMode(*lod);
    }
    if (pointBudget) {
        settings.pointBudget = *pointBudget;
    }
}

LoadedScan loadStreamedView(const lod::NodeSource& source, std::span<const Camera> cameras,
                            std::uint64_t pointBudget) {
    LoadedScan scan = lod::loadStreamedScan(source, lod::selectNodes(source, cameras, pointBudget));
    for (const std::string& warning : scan.warnings) {
        fmt::print(stderr, "subscan: warning: {}: {}\n", source.info().name, warning);
    }
    return scan;
}

void printSourceWarnings(const PointRecordSourceInfo& info) {
    for (const std::string& warning : info.warnings) {
        fmt::print(stderr, "subscan: warning: {}\n", warning);  // each names its input
    }
}

bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ignored;  // a path that does not exist is no other file
    return std::filesystem::equivalent(a, b, ignored);
}

std::optional<glm::dvec3> parseCommaSeparatedTriple(const std::string& text) {
    glm::dvec3 value;
    char comma1 = 0, comma2 = 0;
    std::istringstream stream(text);
    stream >> value.x >> comma1 >> value.y >> comma2 >> value.z;
    if (!stream || comma1 != ',' || comma2 != ',' || !stream.eof()) {
        return std::nullopt;
    }
    return value;
}

std::optional<glm::vec3> parseCommaSeparatedRgb(const std::string& text) {
    const std::optional<glm::dvec3> value = parseCommaSeparatedTriple(text);
    constexpr double kLargestFloat = std::numeric_limits<float>::max();
    if (!value || glm::any(glm::greaterThan(glm::abs(*value), glm::dvec3(kLargestFloat)))) {
        return std::nullopt;
    }
    return glm::vec3(*value);
}

void addResolutionOption(CLI::App& command, std::string& resolution) {
    command
        .add_option("--resolution", resolution,
                    "Pixels the surface is reconstructed at: full (default) | half | auto (half "
                    "while the points are 4 or more pixels apart)")
        ->check(CLI::IsMember({"full", "half", "auto"}));
}

namespace {

/// A check of a number option against its scattering setting's range (`problem`, which says
/// why a value is outside it): a bad value is a usage error, and CLI11 names the option.
template <class Number>
CLI::Validator scatteringRange(std::optional<std::string> (*problem)(Number)) {
    return CLI::Validator(
        [problem](std::string& text) {
            Number value{};
            if (!CLI::detail::lexical_cast(text, value)) {
                return std::string();  // not a number: the option's conversion says so
            }
            const std::optional<std::string> why = problem(value);
            return why ? fmt::format("{} {}", text, *why) : std::string();
        },
        "");
}

}  // namespace

void ScatteringOptions::add(CLI::App& command) {
    const std::size_t before = command.get_options().size();
    command
        .add_option("--scattering", method,
                    "Light transport of the sss mode: gaussian (blur of the diffuse light) | "
                    "single (single scattering) | both")
        ->check(CLI::IsMember({"gaussian", "single", "both"}));
    command
        .add_option("--material", material,
                    "Translucent material of the sss mode (see `subscan materials`)")
        ->check(parsedBy([](const std::string& name) { findMaterial(name); }));
    command.add_option("--unit", unit, "Length unit of the scan: mm | cm | m | in")
        ->check(CLI::IsMember({"mm", "cm", "m", "in"}));
    command
        .add_option("--sss-scale", scale,
                    "Multiplies every scattering radius and mean free path (0 < scale <= 1000)")
        ->check(finiteNumber())
        ->check(scatteringRange(scaleProblem));
    command
        .add_option("--albedo", albedo,
                    "Where the colour enters the Gaussian blur: pre | post | split")
        ->check(CLI::IsMember({"pre", "post", "split"}));
    command
        .add_option("--coefficients", coefficients,
                    "Single scattering's σs′ and σa: color (from the scan's colour, default) | "
                    "material (measured, see `subscan materials`)")
        ->check(CLI::IsMember({"material", "color"}));
    command
        .add_option("--mean-free-path", meanFreePath,
                    "R,G,B diffuse mean free path in mm for --coefficients color (default: "
                    "measured marble's 8.51,5.57,3.95)")
        ->check(CLI::Validator(
            [](std::string& text) {
                const std::optional<glm::vec3> path = parseCommaSeparatedRgb(text);
                if (!path) {
                    return fmt::format("'{}' is not R,G,B (three millimetre values)", text);
                }
                const std::optional<std::string> why = meanFreePathProblem(*path);
                return why ? fmt::format("{} {}", text, *why) : std::string();
            },
            ""));
    command
        .add_option("--eta", eta,
                    "Relative index of refraction (default: the material's); overrides the "
                    "material's for both coefficient sources")
        ->check(finiteNumber())
        ->check(scatteringRange(etaProblem));
    command.add_option("--phase-g", phaseG, "Henyey-Greenstein asymmetry g, -1 < g < 1")
        ->check(finiteNumber())
        ->check(scatteringRange(phaseGProblem));
    command
        .add_option("--single-samples", singleSamples,
                    "Samples along the refracted view ray (1..64)")
        ->check(scatteringRange(singleSamplesProblem));
    command
        .add_option("--light-path", lightPath,
                    "Where single scattering finds a directional light's entry: light_map (the "
                    "light's own reconstruction, default) | screen (a march through the camera's)")
        ->check(CLI::IsMember({"screen", "light_map"}));
    // The options just added: CLI11 keeps a command's options in the order they were added.
    const std::vector<const CLI::Option*> all = std::as_const(command).get_options();
    added.assign(all.begin() + static_cast<std::ptrdiff_t>(before), all.end());
}

void ScatteringOptions::apply(ScatteringSettings& settings) const {
    if (!method.empty()) {
        settings.method = parseScatteringMethod(method);
    }
    if (!material.empty()) {
        settings.material = findMaterial(material).name;
    }
    if (!unit.empty()) {
        settings.unit = parseSceneUnit(unit);
    }
    if (scale) {
        settings.scale = *scale;
    }
    if (!albedo.empty()) {
        settings.albedo = parseAlbedoPlacement(albedo);
    }
    if (!coefficients.empty()) {
        settings.coefficients = parseCoefficientSource(coefficients);
    }
    if (!meanFreePath.empty()) {
        settings.meanFreePathMm = *parseCommaSeparatedRgb(meanFreePath);  // as add() checked
    }
    if (eta) {
        settings.eta = *eta;
    }
    if (phaseG) {
        settings.phaseG = *phaseG;
    }
    if (singleSamples) {
        settings.singleSamples = *singleSamples;
    }
    if (!lightPath.empty()) {
        settings.lightPath = parseLightPath(lightPath);
    }
    checkScatteringSettings(settings);
}

void SensorViewOptions::add(CLI::App& command) {
    command
        .add_option("--view", view,
                    "orbit (default: --yaw, --pitch around the points) | sensor (from where the "
                    "scan was taken: an organised cloud's own camera, the PCD VIEWPOINT, the E57 "
                    "pose or --sensor)")
        ->check(CLI::IsMember({"orbit", "sensor"}));
    command.add_option_function<std::string>(
        "--sensor",
        [this](const std::string& text) {
            const std::optional<glm::dvec3> position = parseCommaSeparatedTriple(text);
            if (!position) {
                throw CLI::ValidationError(
                    "--sensor",
                    fmt::format(
                        "'{}' is not X,Y,Z (three finite numbers in the file's coordinates)",
                        text));
            }
            sensor = position;
        },
        "The sensor's position X,Y,Z in the file's coordinates (for --view sensor)");
}

Camera SensorViewOptions::camera(const LoadedScan& scan, const std::string& source, UpAxis up,
                                 int width, int height, bool sizeGiven, double fovyDegrees) const {
    // --sensor overrides what the file says, the organised grid's camera included.
    const OrganisedGrid noGrid;
    std::vector<std::string> warnings;
    try {
        const Camera camera = viewFromSensor(
            scan.cloud, sensor ? noGrid : scan.grid,
            sensor ? std::optional<SensorPose>(SensorPose{*sensor, "--sensor"}) : scan.sensor, up,
            width, height, sizeGiven, fovyDegrees, warnings);
        for (const std::string& warning : warnings) {
            fmt::print(stderr, "subscan: warning: {}: {}\n", source, warning);
        }
        return camera;
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", source, error.what()));
    }
}

}  // namespace subscan::cli
