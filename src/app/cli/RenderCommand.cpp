#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Error.h"
#include "core/Srgb.h"
#include "gpu/GlContext.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "render/RenderSettings.h"
#include "render/Renderer.h"

namespace subscan::cli {

namespace {

struct RenderOptions {
    std::string source;
    std::string output;
    int width = 1280;
    int height = 720;
    std::string mode;
    std::optional<float> pointSize;
    double yaw = 30.0;
    double pitch = 20.0;
    std::optional<double> distance;
    std::string up = "auto";
    double fovy = 45.0;
    std::string cameraFile;
    std::string background;
    std::string exportDirectory;
    std::string raster;
    std::string resolution;
    std::string stage;
    ScatteringOptions scattering;
    std::string settingsFile;
    std::string saveSettingsFile;
    int samples = 1;
    bool timings = false;
    bool verbose = false;
    bool software = false;
};

/// "R,G,B" with sRGB components in 0..1, or "#rrggbb".
glm::vec3 parseBackground(const std::string& text) {
    if (text.size() == 7 && text[0] == '#') {
        const unsigned long value = std::stoul(text.substr(1), nullptr, 16);
        return glm::vec3((value >> 16) & 255, (value >> 8) & 255, value & 255) / 255.0f;
    }
    const std::optional<glm::vec3> color = parseCommaSeparatedRgb(text);
    if (!color || glm::any(glm::lessThan(*color, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(*color, glm::vec3(1.0f)))) {
        throw Error(
            fmt::format("--background '{}' is not R,G,B with values in 0..1 or #rrggbb", text));
    }
    return *color;
}

bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ignored;
    return std::filesystem::equivalent(a, b, ignored);
}

/// Per-pass median over `timed` frames after one warm-up (llvmpipe compiles shaders lazily and
/// buffers are allocated on the first frame).
std::vector<PassTiming> medianTimings(Renderer& renderer, const Camera& camera,
                                      const RenderSettings& settings, FrameOutputs outputs,
                                      int timed) {
    renderer.render(camera, settings, outputs);
    std::vector<std::vector<PassTiming>> frames;
    for (int i = 0; i < timed; ++i) {
        frames.push_back(renderer.render(camera, settings, outputs).passes);
    }
    std::vector<PassTiming> medians = frames.front();
    for (std::size_t pass = 0; pass < medians.size(); ++pass) {
        std::vector<double> values;
        for (const auto& frame : frames) {
            values.push_back(frame[pass].milliseconds);
        }
        std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
        medians[pass].milliseconds = values[values.size() / 2];
    }
    return medians;
}

/// Keeps `channels` of the 4 in an RGBA float image (for PFM, which holds 1 or 3).
ImageF channelsOf(const Texture& texture, int channels) {
    const std::vector<float> rgba = texture.readFloats();
    ImageF image{texture.width(), texture.height(), channels, {}};
    const std::size_t pixels = rgba.size() / 4;
    image.values.reserve(pixels * static_cast<std::size_t>(channels));
    for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
        for (int c = 0; c < channels; ++c) {
            image.values.push_back(rgba[4 * pixel + static_cast<std::size_t>(c)]);
        }
    }
    return image;
}

/// camera.json, depth.pfm and color.png always; in the surface and sss modes also normals.pfm,
/// mask.png and radiance.pfm (after scattering in sss mode), with depth.pfm holding the
/// reconstructed depth (+inf outside the mask); with single scattering also single.pfm (that
/// term alone, linear RGB like radiance.pfm), sigma_s.pfm and sigma_a.pfm (σs′ and σa in mm⁻¹). The
/// camera and the buffers are the pipeline's: at reduced resolution, smaller than the picture.
void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings) {
    const RenderMode mode = settings.raster.mode;
    const Camera& camera = renderer.pipelineCamera();
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) {
        throw Error(fmt::format("{}: cannot create the directory: {}", directory.string(),
                                error.message()));
    }
    const FrameResources& resources = renderer.resources();
    const bool surface = reconstructsSurface(mode);
    writeCameraFile(directory / "camera.json", camera);
    const Texture& depthTexture = resources.texture(surface ? "surfaceDepth" : "depth");
    const std::vector<float> depth = depthTexture.readFloats();
    writePfm(directory / "depth.pfm", {camera.width, camera.height, 1, depth});

    // color.png: the point (or filled) colour, sRGB, alpha 0 where nothing is.
    const std::vector<float> color =
        resources.texture(surface ? "filledColor" : "color").readFloats();
    Image8 png{camera.width, camera.height, 4, std::vector<std::uint8_t>(color.size())};
    for (std::size_t pixel = 0; pixel < depth.size(); ++pixel) {
        const bool empty = std::isinf(depth[pixel]);  // the fill's colour reaches past the mask
        for (std::size_t c = 0; c < 3; ++c) {
            png.pixels[4 * pixel + c] = empty ? 0 : srgb8Channel(color[4 * pixel + c]);
        }
        png.pixels[4 * pixel + 3] = empty ? 0 : 255;
    }
    writePng(directory / "color.png", png);
    if (!surface) {
        return;
    }
    writePfm(directory / "normals.pfm", channelsOf(resources.texture("normals"), 3));
    const bool scattered = mode == RenderMode::Sss && resources.has("scatteredRadiance");
    writePfm(directory / "radiance.pfm",
             channelsOf(resources.texture(scattered ? "scatteredRadiance" : "radiance"), 3));
    Image8 mask{camera.width, camera.height, 1, std::vector<std::uint8_t>(depth.size())};
    for (std::size_t pixel = 0; pixel < depth.size(); ++pixel) {
        mask.pixels[pixel] = std::isinf(depth[pixel]) ? 0 : 255;
    }
    writePng(directory / "mask.png", mask);
    if (scattered && settings.scattering.method != ScatteringMethod::Gaussian) {
        writePfm(directory / "single.pfm", channelsOf(resources.texture("singleScattering"), 3));
        writePfm(directory / "sigma_s.pfm", channelsOf(resources.texture("sigmaSPrime"), 3));
        writePfm(directory / "sigma_a.pfm", channelsOf(resources.texture("sigmaA"), 3));
    }
}

int runRender(const RenderOptions& options) {
    const std::filesystem::path output = options.output;
    if (!options.source.starts_with("synthetic:") && sameFile(output, options.source)) {
        throw Error(
            fmt::format("{}: refusing to write the image over the input scan", options.output));
    }

    RenderSettings settings;
    if (!options.settingsFile.empty()) {
        settings = readSettingsFile(options.settingsFile);
    }
    RasterSettings& raster = settings.raster;
    if (!options.mode.empty()) {
        raster.mode = parseRenderMode(options.mode);
    }
    if (options.pointSize) {
        raster.pointSize = *options.pointSize;
    }
    if (!options.raster.empty()) {
        raster.path = parseRasterPath(options.raster);
    }
    if (!options.resolution.empty()) {
        raster.resolution = parseResolution(options.resolution);
    }
    if (!options.stage.empty()) {
        raster.stage = parseStage(options.stage);
    }
    if (!options.background.empty()) {
        raster.backgroundSrgb = parseBackground(options.background);
    }
    options.scattering.apply(settings.scattering);
    if (options.samples > 1) {
        if (!reconstructsSurface(raster.mode) || raster.stage != Stage::Final) {
            throw Error(
                "--samples needs the final picture of the surface or sss mode (the temporal "
                "filter anti-aliases reconstructed surfaces)");
        }
        // A still camera's frames are averaged evenly up to max_frames of them.
        settings.temporal.enabled = true;
        settings.temporal.maxFrames = std::max(settings.temporal.maxFrames, options.samples);
    }
    if (!options.saveSettingsFile.empty()) {
        writeSettingsFile(options.saveSettingsFile, settings);
    }

    const LoadedScan scan = loadScanForCommand(options.source);
    Camera camera;
    if (!options.cameraFile.empty()) {
        camera = readCameraFile(options.cameraFile);
    } else {
        OrbitView orbit;
        orbit.yawDegrees = options.yaw;
        orbit.pitchDegrees = options.pitch;
        orbit.distance = options.distance;
        orbit.up = options.up == "z" || (options.up == "auto" && scan.format == "las") ? UpAxis::Z
                                                                                       : UpAxis::Y;
        camera = orbitCamera(scan.cloud.bounds, orbit, options.width, options.height, options.fovy);
    }

    HeadlessContextOptions contextOptions;
    contextOptions.preferHardware = !options.software;
#ifndef NDEBUG
    contextOptions.debugOutput = true;  // debug builds turn GL errors into errors
#endif
    const std::unique_ptr<GlContext> context = createHeadlessContext(contextOptions);
    if (options.verbose) {
        const GlCapabilities& caps = context->capabilities();
        fmt::print(stderr, "subscan: OpenGL {} | {} | {}\n", caps.version, caps.vendor,
                   caps.renderer);
    }
    Renderer renderer(*context, scan.cloud);
    const FrameOutputs outputs =
        options.exportDirectory.empty() ? FrameOutputs::Picture : FrameOutputs::Everything;
    if (options.timings) {
        // With --samples the frames timed are the ones averaged, so the picture stays theirs.
        const std::vector<PassTiming> timings = medianTimings(
            renderer, camera, settings, outputs, options.samples > 1 ? options.samples - 1 : 3);
        double total = 0.0;
        for (const PassTiming& timing : timings) {
            fmt::print("{:<20} {:9.3f} ms\n", timing.pass, timing.milliseconds);
            total += timing.milliseconds;
        }
        fmt::print("{:<20} {:9.3f} ms\n", "total", total);
    } else {
        for (int frame = 0; frame < options.samples; ++frame) {
            renderer.render(camera, settings, outputs);
        }
    }

    if (!options.exportDirectory.empty()) {
        exportBuffers(options.exportDirectory, renderer, settings);
    }
    writePng(output, {camera.width, camera.height, 4, renderer.readImage()});
    return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& parent) {
    auto options = std::make_shared<RenderOptions>();
    CLI::App* render = parent.add_subcommand("render", "Render one image headless (EGL)");
    render->add_option("scan", options->source, "Scan file, or synthetic:NAME")->required();
    render->add_option("-o,--output", options->output, "PNG to write")->required();
    render->add_option("--width", options->width, "Image width in pixels")
        ->check(CLI::Range(1, 65536));
    render->add_option("--height", options->height, "Image height in pixels")
        ->check(CLI::Range(1, 65536));
    render
        ->add_option("--mode", options->mode,
                     "points (default) | points-gl | splats | surface | sss (surface with "
                     "subsurface scattering)")
        ->check(CLI::IsMember({"points", "points-gl", "splats", "surface", "sss"}));
    render
        ->add_option("--stage", options->stage,
                     "Show an intermediate: depth | pyramid | visibility | pull | push | fill | "
                     "normals | shaded (surface and sss modes; depth in any)")
        ->check(CLI::IsMember({"final", "depth", "pyramid", "visibility", "pull", "push", "fill",
                               "normals", "shaded"}));
    options->scattering.add(*render);
    render->add_option("--point-size", options->pointSize, "Splat size in pixels (splats mode)")
        ->check(CLI::Range(1.0f, 64.0f));
    render->add_option("--yaw", options->yaw, "Orbit angle around the up axis, degrees");
    render->add_option("--pitch", options->pitch, "Orbit elevation, degrees")
        ->check(CLI::Range(-90.0, 90.0));
    render
        ->add_option("--distance", options->distance,
                     "Eye distance from the centre (scene units); default frames the bounds")
        ->check(CLI::PositiveNumber);
    render->add_option("--up", options->up, "Up axis: auto (z for LAS, else y) | y | z")
        ->check(CLI::IsMember({"auto", "y", "z"}));
    render->add_option("--fovy", options->fovy, "Vertical field of view, degrees")
        ->check(CLI::Range(1.0, 170.0));
    render->add_option("--camera", options->cameraFile, "camera.json to render from")
        ->check(CLI::ExistingFile);
    render->add_option("--background", options->background, "R,G,B (sRGB 0..1) or #rrggbb");
    render->add_option("--export-buffers", options->exportDirectory,
                       "Directory for camera.json, depth.pfm, color.png");
    render->add_option("--raster", options->raster, "Compute rasterizer: auto | int64 | two-pass")
        ->check(CLI::IsMember({"auto", "int64", "two-pass"}));
    addResolutionOption(*render, options->resolution);
    render
        ->add_option("--settings", options->settingsFile,
                     "Settings JSON ({\"raster\", \"surface\", \"shading\", \"scattering\"}); "
                     "options given "
                     "here override it")
        ->check(CLI::ExistingFile);
    render->add_option("--save-settings", options->saveSettingsFile,
                       "Write the effective settings as JSON");
    render
        ->add_option("--samples", options->samples,
                     "Anti-alias the surface: the mean of this many frames through sub-pixel "
                     "jittered cameras (the temporal filter, still camera)")
        ->check(CLI::Range(1, 2048));
    render->add_flag("--timings", options->timings, "Print per-pass milliseconds");
    render->add_flag("-v,--verbose", options->verbose, "Print the OpenGL renderer");
    render->add_flag("--software", options->software,
                     "Use Mesa's software rasterizer even when a GPU exists");
    return {render, [options] { return runRender(*options); }};
}

}  // namespace subscan::cli
