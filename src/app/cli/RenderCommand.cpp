#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

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
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "render/FrameBuffers.h"
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

/// A .pfm or .exr picture is the radiance buffer of --export-buffers (the shaded surface before
/// the display transform): refused, before anything renders, where the picture is not that.
void checkLinearPictureRequest(const std::filesystem::path& output, const RenderSettings& settings,
                               int samples) {
    const RasterSettings& raster = settings.raster;
    const auto refuse = [&](std::string_view why) {
        throw Error(
            fmt::format("{}: a .pfm or .exr picture is the linear radiance of the shaded "
                        "surface; {}",
                        output.string(), why));
    };
    if (!reconstructsSurface(raster.mode)) {
        refuse("it needs --mode surface or sss (the points modes shade nothing)");
    }
    if (raster.stage != Stage::Final) {
        refuse("a --stage view has none (write it as .png)");
    }
    if (samples > 1) {
        refuse(
            "it is one frame's, so it needs --samples 1 (the temporal filter averages the "
            "8-bit picture only)");
    }
    if (raster.resolution != Resolution::Full) {
        refuse(
            "it needs --resolution full (at reduced resolution the radiance is smaller than "
            "the picture)");
    }
}

/// The radiance buffer of the last frame (rendered with FrameOutputs::Everything).
ImageF radianceOf(const Renderer& renderer, const RenderSettings& settings) {
    for (FrameBuffer& buffer : readFrameBuffers(renderer, settings)) {
        if (buffer.name == "radiance") {
            return std::move(buffer.image);
        }
    }
    throw Error("the frame has no radiance buffer (only the surface and sss modes shade)");
}

int runRender(const RenderOptions& options) {
    const FrameOptions& frame = options.frame;
    const std::filesystem::path output = options.output;
    frame.refuseToOverwriteInputs(output, "the image");
    const bool linearPicture = holdsLinearRadiance(pictureFormat(output));
    frame.refuseToOverwriteInputs(frame.saveSettingsFile, "the settings");
    requireOutputFolder(output);
    requireOutputFolder(frame.saveSettingsFile);
    if (!options.exportDirectory.empty()) {
        // The picture and the settings may go into the folder beside the buffers.
        checkExportFolder(frame, options.exportDirectory, [&](const std::filesystem::path& entry) {
            return sameFile(entry, output) || sameFile(entry, frame.saveSettingsFile);
        });
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
    if (linearPicture) {
        checkLinearPictureRequest(output, settings, samples);
    }
    const std::unique_ptr<lod::NodeSource> streamed =
        lod::openStreamed(frame.source, settings.streaming.lod);
    const std::unique_ptr<GlContext> context = frame.context();
    LoadedScan scan;
    Camera camera;
    if (streamed) {
        // Framed by an even sample of the whole survey, then the nodes that view shows.
        camera = frame.camera(lod::loadStreamedOverview(*streamed));
        const std::uint64_t budget =
            lod::pointBudgetFor(settings.streaming.pointBudget, context->capabilities().software);
        scan = loadStreamedView(*streamed, std::span(&camera, 1), budget);
    } else {
        scan = loadScanForCommand(frame.source);
        camera = frame.camera(scan);
    }
    frame.applyColoring(scan);
    // `scan` outlives the renderer unchanged: the GPU may read its points in place.
    Renderer renderer(*context, scan.cloud, estimatePointSpacing(scan.cloud, scan.levelSpacing), 0,
                      PointMemory::Borrow);
    renderer.prepareNormals(scan.cloud, streamed ? streamedNormals(settings.surface.normals)
                                                 : settings.surface.normals);
    // The radiance of a linear picture is one of the buffers the picture alone does not keep.
    const FrameOutputs outputs = options.exportDirectory.empty() && !linearPicture
                                     ? FrameOutputs::Picture
                                     : FrameOutputs::Everything;
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
    ImageF radiance;
    if (linearPicture) {
        radiance = radianceOf(renderer, settings);
    }
    context->throwOnErrors("while rendering");
    // Outputs only once the picture exists, so a failed render leaves none behind.
    if (!options.exportDirectory.empty()) {
        exportBuffers(options.exportDirectory, renderer, settings, camera);
        context->throwOnErrors("while reading the buffers back");
    }
    if (linearPicture) {
        writeLinearPicture(output, radiance);
    } else {
        writePicture(output, picture);
    }
    frame.saveSettings(settings);
    return 0;
}

}  // namespace

Command addRenderCommand(CLI::App& parent) {
    auto options = std::make_shared<RenderOptions>();
    CLI::App* render = parent.add_subcommand("render", "Render one image headless (EGL)");
    options->frame.add(*render);
    render
        ->add_option("-o,--output", options->output,
                     "Picture to write: .png, .jpg or .jpeg (sRGB), or .pfm or .exr (the linear "
                     "radiance of the surface and sss modes, 32-bit float: radiance.pfm of "
                     "--export-buffers)")
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
