#include "app/cli/FrameOptions.h"

#include <fmt/format.h>
#include <glm/vector_relational.hpp>

#include "core/Coloring.h"
#include "core/Error.h"
#include "core/SensorView.h"
#include "io/CameraJson.h"

namespace subscan::cli {

namespace {

/// "R,G,B" with sRGB components in 0..1, or "#rrggbb"; nullopt for anything else.
std::optional<glm::vec3> parseBackground(const std::string& text) {
    if (text.size() == 7 && text[0] == '#' &&
        text.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos) {
        const unsigned long value = std::stoul(text.substr(1), nullptr, 16);
        return glm::vec3((value >> 16) & 255, (value >> 8) & 255, value & 255) / 255.0f;
    }
    const std::optional<glm::vec3> color = parseCommaSeparatedRgb(text);
    if (!color || glm::any(glm::lessThan(*color, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(*color, glm::vec3(1.0f)))) {
        return std::nullopt;
    }
    return color;
}

}  // namespace

void FrameOptions::add(CLI::App& command, RenderMode modeByDefault) {
    defaultMode = modeByDefault;
    command.add_option("scan", source, "Scan file, or synthetic:NAME")->required();
    command.add_option("--width", width, "Image width in pixels")->check(CLI::Range(1, 65536));
    command.add_option("--height", height, "Image height in pixels")->check(CLI::Range(1, 65536));
    command
        .add_option("--mode", mode,
                    fmt::format("points | points-gl | splats | surface | sss (surface with "
                                "subsurface scattering); default: the settings file's, else {}",
                                toString(defaultMode)))
        ->check(CLI::IsMember({"points", "points-gl", "splats", "surface", "sss"}));
    command
        .add_option("--stage", stage,
                    "Show an intermediate: depth | pyramid | visibility | pull | push | fill | "
                    "normals | shaded (surface and sss modes; depth in any)")
        ->check(CLI::IsMember({"final", "depth", "pyramid", "visibility", "pull", "push", "fill",
                               "normals", "shaded"}));
    scattering.add(command);
    command.add_option("--point-size", pointSize, "Splat size in pixels (splats mode)")
        ->check(finiteNumber())
        ->check(CLI::Range(1.0f, 64.0f));
    command.add_option("--yaw", yaw, "Orbit angle around the up axis, degrees")
        ->check(finiteNumber());
    command.add_option("--pitch", pitch, "Orbit elevation, degrees")
        ->check(finiteNumber())
        ->check(CLI::Range(-90.0, 90.0));
    command
        .add_option("--distance", distance,
                    "Eye distance from the centre (scene units); default frames the bounds")
        ->check(finiteNumber())
        ->check(CLI::PositiveNumber);
    command.add_option("--up", up, kUpAxisHelp)->check(CLI::IsMember(kUpAxisNames));
    sensorView.add(command);
    command
        .add_option("--color", color,
                    "What the points' colour shows: auto (rgb, else height for Z-up data, else "
                    "uniform) | rgb | intensity | height | uniform | classification (ASPRS LAS "
                    "class colours)")
        ->check(CLI::IsMember(coloringNames()));
    command.add_option("--fovy", fovy, "Vertical field of view, degrees")
        ->check(finiteNumber())
        ->check(CLI::Range(1.0, 170.0));
    CLI::Option* camera = command.add_option("--camera", cameraFile, "camera.json to render from")
                              ->check(CLI::ExistingFile);
    // The file fixes the size and the view: these were ignored without a word.
    for (const char* placed : {"--width", "--height", "--yaw", "--pitch", "--distance", "--fovy",
                               "--view", "--sensor"}) {
        camera->excludes(command.get_option(placed));
    }
    // A bad colour is a usage error, refused while parsing with the option's name (cli::, not
    // the member parsedBy).
    command.add_option("--background", background, "R,G,B (sRGB 0..1) or #rrggbb")
        ->check(cli::parsedBy([](const std::string& text) {
            if (!parseBackground(text)) {
                throw Error(fmt::format("'{}' is not R,G,B with values in 0..1 or #rrggbb", text));
            }
        }));
    command.add_option("--raster", raster, "Compute rasterizer: auto | int64 | two-pass")
        ->check(CLI::IsMember({"auto", "int64", "two-pass"}));
    addResolutionOption(command, resolution);
    command
        .add_option("--settings", settingsFile,
                    "Settings JSON ({\"raster\", \"surface\", \"shading\", \"scattering\", "
                    "\"temporal\"}); options given here override it")
        ->check(CLI::ExistingFile);
    command.add_option("--save-settings", saveSettingsFile, "Write the effective settings as JSON");
    command.add_flag("-v,--verbose", verbose, "Print the OpenGL renderer");
    command.add_flag("--software", software,
                     "Use Mesa's software rasterizer even when a GPU exists");
    streaming.add(command);
    parsedBy = &command;
}

RenderSettings FrameOptions::settings() const {
    RenderSettings defaults;
    defaults.raster.mode = defaultMode;
    RenderSettings settings = defaults;
    if (!settingsFile.empty()) {
        settings = readSettingsFile(settingsFile, defaults);
    }
    RasterSettings& rasterSettings = settings.raster;
    if (!mode.empty()) {
        rasterSettings.mode = parseRenderMode(mode);
    }
    if (pointSize) {
        rasterSettings.pointSize = *pointSize;
    }
    if (!raster.empty()) {
        rasterSettings.path = parseRasterPath(raster);
    }
    if (!resolution.empty()) {
        rasterSettings.resolution = parseResolution(resolution);
    }
    if (!stage.empty()) {
        rasterSettings.stage = parseStage(stage);
    }
    if (!background.empty()) {
        rasterSettings.backgroundSrgb = *parseBackground(background);  // as add() checked
    }
    scattering.apply(settings.scattering);
    streaming.apply(settings.streaming);
    checkIgnoredOptions(rasterSettings.mode);
    return settings;
}

bool FrameOptions::given(const char* name) const {
    return parsedBy != nullptr && parsedBy->get_option(name)->count() > 0;
}

void FrameOptions::checkIgnoredOptions(RenderMode effectiveMode) const {
    // Each of these was accepted and then ignored without a word. The view's are refused; the
    // mode's are only warned of, since --save-settings keeps them for the other modes.
    if (sensorView.wanted()) {
        for (const char* orbit : {"--yaw", "--pitch", "--distance"}) {
            if (given(orbit)) {
                throw Error(fmt::format(
                    "{} has no effect with --view sensor: the view is the sensor's", orbit));
            }
        }
    } else if (given("--sensor")) {
        throw Error("--sensor places the sensor of --view sensor: add --view sensor");
    }
    if (given("--point-size") && effectiveMode != RenderMode::Splats) {
        fmt::print(stderr,
                   "subscan: warning: --point-size is the splats' size: it has no effect on the "
                   "{} mode's picture\n",
                   toString(effectiveMode));
    }
    if (effectiveMode != RenderMode::Sss) {
        for (const CLI::Option* option : scattering.added) {
            if (option->count() > 0) {
                fmt::print(stderr,
                           "subscan: warning: {} sets the subsurface scattering of the sss mode: "
                           "it has no effect on the {} mode's picture\n",
                           option->get_name(), toString(effectiveMode));
            }
        }
    }
}

void FrameOptions::applyColoring(LoadedScan& scan) const {
    try {
        scan.cloud.colors = pointColors(scan.cloud, parseColoring(color), upAxis(scan));
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", source, error.what()));
    }
}

UpAxis FrameOptions::upAxis(const LoadedScan& scan) const {
    return upAxisForScan(up, scan.format, scan.cloud, scan.grid);
}

Camera FrameOptions::camera(const LoadedScan& scan, Framing framing) const {
    if (!cameraFile.empty()) {
        return readCameraFile(cameraFile);
    }
    if (sensorView.wanted()) {
        return sensorView.camera(scan, source, upAxis(scan), width, height,
                                 given("--width") || given("--height"), fovy);
    }
    OrbitView orbit;
    orbit.yawDegrees = yaw;
    orbit.pitchDegrees = pitch;
    orbit.distance = distance;
    orbit.up = upAxis(scan);
    orbit.framing = framing;
    orbit.framed = framingBounds(scan.cloud);
    return orbitCamera(scan.cloud.bounds, orbit, width, height, fovy);
}

std::unique_ptr<GlContext> FrameOptions::context() const {
    HeadlessContextOptions options;
    options.preferHardware = !software;
    options.debugOutput = glDebugOutputRequested();
    std::unique_ptr<GlContext> context = createHeadlessContext(options);
    if (verbose) {
        const GlCapabilities& caps = context->capabilities();
        fmt::print(stderr, "subscan: OpenGL {} | {} | {}\n", caps.version, caps.vendor,
                   caps.renderer);
    }
    return context;
}

const char* FrameOptions::inputKindOf(const std::filesystem::path& file) const {
    for (const auto& [input, kind] :
         {std::pair{&source, "scan"}, std::pair{&settingsFile, "settings file"},
          std::pair{&cameraFile, "camera file"}}) {
        if (!input->empty() && !input->starts_with("synthetic:") && sameFile(file, *input)) {
            return kind;
        }
    }
    return nullptr;
}

bool FrameOptions::isInput(const std::filesystem::path& file) const {
    return inputKindOf(file) != nullptr;
}

void FrameOptions::refuseToOverwriteInputs(const std::filesystem::path& output,
                                           std::string_view what) const {
    if (const char* kind = inputKindOf(output)) {
        throw Error(
            fmt::format("{}: refusing to write {} over the input {}", output.string(), what, kind));
    }
}

void FrameOptions::saveSettings(const RenderSettings& settings) const {
    if (!saveSettingsFile.empty()) {
        refuseToOverwriteInputs(saveSettingsFile, "the settings");
        writeSettingsFile(saveSettingsFile, settings);
    }
}

}  // namespace subscan::cli
