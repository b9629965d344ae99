// `subscan bench SCAN`: the paper's measurement (average and 1 % low FPS while a person turns
// the scan around) as a repeatable benchmark: every mode replays the same camera path.
#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <epoxy/gl.h>
#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/CameraPath.h"
#include "core/Error.h"
#include "core/SensorView.h"
#include "gpu/GlContext.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "render/Renderer.h"

namespace subscan::cli {

namespace {

struct BenchOptions {
    std::string source;
    int frames = 600;
    int warmup = 10;
    int width = 1920;
    int height = 1080;
    std::string modes = "points-gl,points,surface,sss";
    ScatteringOptions scattering;
    std::string settingsFile;
    std::string resolution;
    std::string up = "auto";
    SensorViewOptions sensorView;
    CLI::Option* widthOption = nullptr;
    CLI::Option* heightOption = nullptr;
    bool json = false;
    bool software = false;
    StreamingOptions streaming;
};

/// One entry of --modes: a render mode, then optional suffixes after ':' — `sss:METHOD` the
/// scattering method that replaces the settings' one, `:no-shadows` (surface and sss) the
/// directional lights without their light maps. Its name (as given) names the run.
struct BenchMode {
    std::string name;
    RenderMode mode = RenderMode::Points;
    std::optional<ScatteringMethod> method;
    bool noShadows = false;
};

/// The passes that turn the points into a surface (DESIGN.md §5), whose sum is a run's
/// `reconstruction_ms`: the yardstick that the scattering passes are measured against.
constexpr std::string_view kReconstructionPasses[] = {"RasterizePoints",    "MinDepthPyramid",
                                                      "HiddenPointRemoval", "PullPush",
                                                      "FillRemoval",        "Normals"};
constexpr std::string_view kSingleScatteringPass = "SingleScattering";
constexpr std::string_view kNoShadows = "no-shadows";

BenchMode parseMode(const std::string& name) {
    BenchMode entry{name};
    std::stringstream parts(name);
    std::string part;
    std::getline(parts, part, ':');
    entry.mode = parseRenderMode(part);
    while (std::getline(parts, part, ':')) {
        if (part == kNoShadows && reconstructsSurface(entry.mode)) {
            entry.noShadows = true;
            continue;
        }
        if (entry.mode == RenderMode::Sss && !entry.method) {
            try {
                entry.method = parseScatteringMethod(part);
                continue;
            } catch (const Error&) {
            }
        }
        throw Error(
            fmt::format("'{}' in '{}' is neither a scattering method of the sss mode "
                        "(sss:gaussian, sss:single or sss:both) nor no-shadows (surface and sss)",
                        part, name));
    }
    return entry;
}

/// The entries of a --modes list; throws subscan::Error saying what is wrong with it, which the
/// option's check gives CLI11 to name the option with.
std::vector<BenchMode> parseModes(const std::string& list) {
    std::vector<BenchMode> modes;
    std::set<std::string> names;
    std::stringstream stream(list);
    std::string name;
    while (std::getline(stream, name, ',')) {
        if (!names.insert(name).second) {
            throw Error(fmt::format("'{}' is named twice", name));
        }
        modes.push_back(parseMode(name));
    }
    if (modes.empty()) {
        throw Error("no render mode is named");
    }
    return modes;
}

double mean(const std::vector<double>& values) {
    return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// One mode along the camera path: a renderer and settings of its own, so that the memory it
/// reports is this mode's alone, and its frame and pass times.
struct ModeRun {
    ModeRun(GlContext& context, const PointCloud& cloud, const PointSpacing& spacing,
            const std::vector<glm::vec3>& normals, RenderSettings modeSettings,
            const BenchMode& mode)
        : settings(std::move(modeSettings)), renderer(context, cloud, spacing) {
        if (!normals.empty()) {
            renderer.setPointNormals(normals);
        }
        settings.raster.mode = mode.mode;
        settings.raster.stage = Stage::Final;
        if (mode.method) {
            settings.scattering.method = *mode.method;
        }
        if (mode.noShadows) {
            settings.shading.shadows = false;
        }
    }

    bool usesLightMaps() const { return subscan::usesLightMaps(settings); }

    /// The cost of building every light's map (the sum of the light-map passes of a frame
    /// that rebuilds them), median of `builds`: each turns the lights by a thousandth of a
    /// radian, which a map cannot keep.
    double lightMapBuildMs(const Camera& camera, int builds) {
        RenderSettings turned = settings;
        std::vector<double> totals;
        for (int build = 0; build < builds; ++build) {
            for (DirectionalLight& light : turned.shading.lights) {
                // A thousandth of a radian about an axis across the light.
                const glm::vec3 along = glm::normalize(light.direction);
                const glm::vec3 other = std::abs(along.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f)
                                                                 : glm::vec3(0.0f, 1.0f, 0.0f);
                light.direction = along + 1e-3f * glm::normalize(glm::cross(along, other));
            }
            double total = 0.0;
            for (const PassTiming& pass : renderer.render(camera, turned).passes) {
                total += pass.pass.starts_with(kLightMapPassPrefix) ? pass.milliseconds : 0.0;
            }
            glFinish();
            totals.push_back(total);
        }
        renderer.render(camera, settings);  // the run's own lights again
        return median(totals);
    }

    /// Renders one frame and waits for it: a frame is done when its image is, with no overlap
    /// with the next one.
    FrameResult render(const Camera& camera) {
        FrameResult result = renderer.render(camera, settings);
        glFinish();
        return result;
    }

    RenderSettings settings;
    Renderer renderer;
    std::vector<double> frameMs;
    std::map<std::string, std::vector<double>> passMs;
    std::vector<double> reconstructionMs;  // per frame, the sum of kReconstructionPasses
    int reducedFrames = 0;
    std::optional<double> lightMapMs;  // lightMapBuildMs(), for runs that use light maps
};

nlohmann::json summary(const ModeRun& run, std::size_t points) {
    const std::vector<double>& frameMs = run.frameMs;
    const double totalMs = std::accumulate(frameMs.begin(), frameMs.end(), 0.0);
    std::vector<double> slowest = frameMs;
    std::sort(slowest.begin(), slowest.end(), std::greater<>());
    const std::size_t lowCount = (slowest.size() + 99) / 100;  // the slowest 1 %, at least one
    const double lowMs =
        std::accumulate(slowest.begin(), slowest.begin() + static_cast<std::ptrdiff_t>(lowCount),
                        0.0) /
        static_cast<double>(lowCount);
    const double averageFps = 1000.0 * static_cast<double>(frameMs.size()) / totalMs;
    nlohmann::json perPass = nlohmann::json::object();
    nlohmann::json perPassMean = nlohmann::json::object();
    for (const auto& [pass, values] : run.passMs) {
        perPass[pass] = median(values);
        perPassMean[pass] = mean(values);
    }
    const std::size_t bytes = run.renderer.gpuCloud().bytes() + run.renderer.resourceBytes();
    nlohmann::json result = {
        {"avg_fps", averageFps},
        {"low1_fps", 1000.0 / lowMs},
        {"frame_ms_median", median(frameMs)},
        {"per_pass_ms", perPass},
        {"per_pass_mean_ms", perPassMean},
        {"points_per_second", averageFps * static_cast<double>(points)},
        {"gpu_memory_mb", static_cast<double>(bytes) / (1024.0 * 1024.0)},
        {"reduced_resolution_frames", run.reducedFrames},
    };
    if (run.settings.raster.mode == RenderMode::Sss) {
        result["scattering_method"] = toString(run.settings.scattering.method);
    }
    if (reconstructsSurface(run.settings.raster.mode)) {
        const double reconstruction = mean(run.reconstructionMs);
        result["reconstruction_ms"] = reconstruction;
        if (const auto single = run.passMs.find(std::string(kSingleScatteringPass));
            single != run.passMs.end()) {
            result["single_scattering_ratio"] = mean(single->second) / reconstruction;
        }
    }
    if (run.lightMapMs) {
        result["light_map_build_ms"] = *run.lightMapMs;
        result["light_maps"] = run.renderer.lightMaps().maps().size();
    }
    return result;
}

/// Frame `frame` of the benchmark's camera path around `bounds`.
Camera pathCamera(const Bounds& bounds, const BenchOptions& options, UpAxis up, int frame) {
    const double t = options.frames > 1 ? double(frame) / (options.frames - 1) : 0.0;
    return cameraForPose(bounds, benchmarkPose(t), up, options.width, options.height, 45.0);
}

/// Every mode along the same camera path, frame by frame in turn (frame 0 of each mode, then
/// frame 1, ...): a machine whose speed drifts over minutes (a shared virtual machine, a GPU
/// warming up) then slows every mode alike instead of whichever ran last.
std::vector<nlohmann::json> benchModes(GlContext& context, const LoadedScan& scan,
                                       const RenderSettings& settings,
                                       const std::vector<BenchMode>& modes,
                                       const BenchOptions& options, UpAxis up,
                                       const std::optional<Camera>& still) {
    auto cameraAt = [&](int frame) {
        return still ? *still : pathCamera(scan.cloud.bounds, options, up, frame);
    };
    std::vector<std::unique_ptr<ModeRun>> runs;
    // Once for every mode's renderer; a streamed survey's as `render` makes them.
    const bool streamed = !scan.levelSpacing.empty();
    const PointSpacing spacing = estimatePointSpacing(scan.cloud, scan.levelSpacing);
    const std::vector<glm::vec3> normals =
        normalsFor(scan.cloud,
                   streamed ? streamedNormals(settings.surface.normals) : settings.surface.normals);
    for (const BenchMode& mode : modes) {
        runs.push_back(
            std::make_unique<ModeRun>(context, scan.cloud, spacing, normals, settings, mode));
        for (int frame = 0; frame < options.warmup; ++frame) {
            runs.back()->render(cameraAt(frame * options.frames / std::max(options.warmup, 1)));
        }
    }
    for (int frame = 0; frame < options.frames; ++frame) {
        const Camera camera = cameraAt(frame);
        for (const std::unique_ptr<ModeRun>& run : runs) {
            const auto start = std::chrono::steady_clock::now();
            const FrameResult result = run->render(camera);
            run->frameMs.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
            double reconstruction = 0.0;
            for (const PassTiming& pass : result.passes) {
                run->passMs[pass.pass].push_back(pass.milliseconds);
                if (std::find(std::begin(kReconstructionPasses), std::end(kReconstructionPasses),
                              pass.pass) != std::end(kReconstructionPasses)) {
                    reconstruction += pass.milliseconds;
                }
            }
            run->reconstructionMs.push_back(reconstruction);
            run->reducedFrames += result.divisor == 1 ? 0 : 1;
        }
    }
    constexpr int kLightMapBuilds = 5;
    std::vector<nlohmann::json> summaries;
    for (const std::unique_ptr<ModeRun>& run : runs) {
        if (run->usesLightMaps()) {
            run->lightMapMs = run->lightMapBuildMs(cameraAt(0), kLightMapBuilds);
        }
        summaries.push_back(summary(*run, scan.cloud.size()));
    }
    return summaries;
}

int runBench(const BenchOptions& options) {
    const std::vector<BenchMode> modes = parseModes(options.modes);  // as --modes' check did
    RenderSettings settings;
    if (!options.settingsFile.empty()) {
        settings = readSettingsFile(options.settingsFile);
    }
    options.scattering.apply(settings.scattering);
    if (!options.resolution.empty()) {
        settings.raster.resolution = parseResolution(options.resolution);
    }
    options.streaming.apply(settings.streaming);
    HeadlessContextOptions contextOptions;
    contextOptions.preferHardware = !options.software;
    contextOptions.debugOutput = glDebugOutputRequested();
    const std::unique_ptr<GlContext> context = createHeadlessContext(contextOptions);
    // A streamed survey: its top levels give the path's bounds (the whole survey's) and the
    // sensor's view; the frames' nodes load once the cameras are known (below).
    const std::unique_ptr<lod::NodeSource> streamed =
        lod::openStreamed(options.source, settings.streaming.lod);
    LoadedScan scan =
        streamed ? lod::loadStreamedOverview(*streamed) : loadScanForCommand(options.source);
    const UpAxis up = upAxisForScan(options.up, scan.format, scan.cloud, scan.grid);
    // --view sensor: every frame from the sensor, a still camera instead of the path.
    std::optional<Camera> still;
    if (options.sensorView.wanted()) {
        still = options.sensorView.camera(
            scan, options.source, up, options.width, options.height,
            options.widthOption->count() > 0 || options.heightOption->count() > 0, 45.0);
    }
    if (streamed) {
        // One set of nodes for every frame within the budget, as turntable loads them.
        std::vector<Camera> cameras;
        for (int frame = 0; frame < (still ? 1 : options.frames); ++frame) {
            cameras.push_back(still ? *still : pathCamera(scan.cloud.bounds, options, up, frame));
        }
        scan = loadStreamedView(
            *streamed, cameras,
            lod::pointBudgetFor(settings.streaming.pointBudget, context->capabilities().software));
    }
    const int width = still ? still->width : options.width;
    const int height = still ? still->height : options.height;

    nlohmann::json report = {
        {"renderer", context->capabilities().renderer},
        {"points", scan.cloud.size()},
        {"width", width},
        {"height", height},
        {"view", options.sensorView.view},
        {"frames", options.frames},
        {"resolution", toString(settings.raster.resolution)},
        {"modes", nlohmann::json::object()},
    };
    if (!options.json) {
        fmt::print(stderr, "subscan: benchmarking {} frames of each mode in turn\n",
                   options.frames);
    }
    const std::vector<nlohmann::json> summaries =
        benchModes(*context, scan, settings, modes, options, up, still);
    context->throwOnErrors("while benchmarking");
    for (std::size_t i = 0; i < modes.size(); ++i) {
        report["modes"][modes[i].name] = summaries[i];
    }
    if (options.json) {
        fmt::print("{}\n", report.dump(2));
        return 0;
    }
    fmt::print("{} | {} points | {}x{} | {} frames\n", report["renderer"].get<std::string>(),
               scan.cloud.size(), width, height, options.frames);
    fmt::print("{:<22} {:>9} {:>9} {:>11} {:>14} {:>8} {:>8} {:>10} {:>13} {:>13}\n", "mode",
               "avg fps", "1% low", "median ms", "points/s", "GPU MB", "reduced", "recon ms",
               "single/recon", "light map ms");
    for (const BenchMode& mode : modes) {
        const nlohmann::json& m = report["modes"][mode.name];
        const auto optional = [&m](const char* key, int decimals) {
            return m.contains(key) ? fmt::format("{:.{}f}", m[key].get<double>(), decimals)
                                   : std::string("-");
        };
        fmt::print(
            "{:<22} {:>9.2f} {:>9.2f} {:>11.2f} {:>14.3g} {:>8.1f} {:>8} {:>10} {:>13} {:>13}\n",
            mode.name, m["avg_fps"].get<double>(), m["low1_fps"].get<double>(),
            m["frame_ms_median"].get<double>(), m["points_per_second"].get<double>(),
            m["gpu_memory_mb"].get<double>(), m["reduced_resolution_frames"].get<int>(),
            optional("reconstruction_ms", 2), optional("single_scattering_ratio", 3),
            optional("light_map_build_ms", 2));
    }
    return 0;
}

}  // namespace

Command addBenchCommand(CLI::App& parent) {
    auto options = std::make_shared<BenchOptions>();
    CLI::App* bench = parent.add_subcommand(
        "bench", "Frame times of each render mode along a replayed camera path (headless)");
    bench->add_option("scan", options->source, "Scan file, or synthetic:NAME")->required();
    bench->add_option("--frames", options->frames, "Frames per mode (default 600)")
        ->check(CLI::Range(1, 1000000));
    bench->add_option("--warmup", options->warmup, "Untimed frames before each mode (default 10)")
        ->check(CLI::Range(0, 100000));
    options->widthOption =
        bench->add_option("--width", options->width, "Image width (default 1920)")
            ->check(CLI::Range(1, 65536));
    options->heightOption =
        bench->add_option("--height", options->height, "Image height (default 1080)")
            ->check(CLI::Range(1, 65536));
    bench
        ->add_option("--modes", options->modes,
                     "Comma-separated modes (default points-gl,points,surface,sss); "
                     "sss:gaussian, sss:single and sss:both run the sss mode with that "
                     "scattering method (plain sss: the settings' method), each its own run; "
                     "a further :no-shadows (surface, sss) turns the light maps off")
        ->check(parsedBy([](const std::string& list) { parseModes(list); }));
    addResolutionOption(*bench, options->resolution);
    bench->add_option("--settings", options->settingsFile, "Settings JSON for every mode")
        ->check(CLI::ExistingFile);
    bench->add_option("--up", options->up, kUpAxisHelp)->check(CLI::IsMember(kUpAxisNames));
    options->sensorView.add(*bench);
    options->scattering.add(*bench);
    bench->add_flag("--json", options->json, "Print the results as JSON");
    options->streaming.add(*bench);
    bench->add_flag("--software", options->software,
                    "Use Mesa's software rasterizer even when a GPU exists");
    return {bench, [options] { return runBench(*options); }};
}

}  // namespace subscan::cli
