#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/BufferExport.h"
#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "app/cli/FrameOptions.h"
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
    FrameOptions frame;
    std::string output;
    std::string exportDirectory;
    std::optional<int> samples;  // unset: 1, or kTemporalRestFrames with the filter on
    bool timings = false;
};

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

int runRender(const RenderOptions& options) {
    const FrameOptions& frame = options.frame;
    const std::filesystem::path output = options.output;
    frame.refuseToOverwriteInputs(output, "the image");
    checkPictureExtension(output);
    frame.refuseToOverwriteInputs(frame.saveSettingsFile, "the settings");
    if (!options.exportDirectory.empty()) {
        frame.refuseToOverwriteInputs(
            std::filesystem::path(options.exportDirectory) / "camera.json", "the camera");
    }
    RenderSettings settings = frame.settings();
    const RasterSettings& raster = settings.raster;
    // The filter on without --samples: its picture at rest, as the viewer shows it.
    const int samples =
        options.samples.value_or(filtersTemporally(settings) ? kTemporalRestFrames : 1);
    if (samples == 1) {
        settings.temporal.enabled = false;  // one frame: no jitter, nothing to blend
    } else {
        if (!reconstructsSurface(raster.mode) || raster.stage != Stage::Final) {
            throw Error(
                "--samples needs the final picture of the surface or sss mode (the temporal "
                "filter anti-aliases reconstructed surfaces)");
        }
        // A still camera's frames are averaged evenly up to max_frames of them.
        settings.temporal.enabled = true;
        settings.temporal.maxFrames = std::max(settings.temporal.maxFrames, samples);
    }
    LoadedScan scan = loadScanForCommand(frame.source);
    frame.applyColoring(scan);
    const Camera camera = frame.camera(scan);
    const std::unique_ptr<GlContext> context = frame.context();
    Renderer renderer(*context, scan.cloud);
    const FrameOutputs outputs =
        options.exportDirectory.empty() ? FrameOutputs::Picture : FrameOutputs::Everything;
    if (options.timings) {
        // With --samples the frames timed are the ones averaged, so the picture stays theirs.
        const std::vector<PassTiming> timings =
            medianTimings(renderer, camera, settings, outputs, samples > 1 ? samples - 1 : 3);
        double total = 0.0;
        for (const PassTiming& timing : timings) {
            fmt::print("{:<20} {:9.3f} ms\n", timing.pass, timing.milliseconds);
            total += timing.milliseconds;
        }
        fmt::print("{:<20} {:9.3f} ms\n", "total", total);
    } else {
        for (int index = 0; index < samples; ++index) {
            renderer.render(camera, settings, outputs);
        }
    }

    const Image8 picture{camera.width, camera.height, 4, renderer.readImage()};
    context->throwOnErrors("while rendering");
    // Outputs only once the picture exists, so a failed render leaves none behind.
    if (!options.exportDirectory.empty()) {
        exportBuffers(options.exportDirectory, renderer, settings);
        context->throwOnErrors("while reading the buffers back");
    }
    writePicture(output, picture);
    frame.saveSettings(settings);
    return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& parent) {
    auto options = std::make_shared<RenderOptions>();
    CLI::App* render = parent.add_subcommand("render", "Render one image headless (EGL)");
    options->frame.add(*render);
    render->add_option("-o,--output", options->output, "Picture to write: .png, .jpg or .jpeg")
        ->required();
    render->add_option("--export-buffers", options->exportDirectory,
                       "Directory for camera.json, depth.pfm, color.png");
    render
        ->add_option("--samples", options->samples,
                     "Anti-alias the surface: the mean of this many frames through sub-pixel "
                     "jittered cameras (the temporal filter at rest; default 1, or 32 when the "
                     "settings turn the filter on)")
        ->check(CLI::Range(1, 2048));
    render->add_flag("--timings", options->timings, "Print per-pass milliseconds");
    return {render, [options] { return runRender(*options); }};
}

}  // namespace subscan::cli
