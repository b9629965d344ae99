#include "render/Renderer.h"

#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/NormalEstimation.h"
#include "render/DrawPointsPass.h"
#include "render/FinishSurfacePass.h"
#include "render/OutlineCoveragePass.h"
#include "render/PresentPass.h"
#include "render/RasterizePointsPass.h"
#include "render/ShadePass.h"
#include "render/SingleScatteringPass.h"
#include "render/StageViewPass.h"
#include "render/SubsurfaceScatteringPass.h"
#include "render/TemporalPass.h"

namespace subscan {

namespace {

/// h for the screen-space radii; a cloud without two distinct points still needs a scale.
double usableSpacing(const PointCloud& cloud, double h) {
    if (h > 0.0 && std::isfinite(h)) {
        return h;
    }
    const double diagonal = glm::length(cloud.bounds.extent());
    return diagonal > 0.0 ? 1e-3 * diagonal : 1e-3;
}

}  // namespace

double FrameResult::totalMilliseconds() const {
    return std::accumulate(passes.begin(), passes.end(), 0.0,
                           [](double sum, const PassTiming& t) { return sum + t.milliseconds; });
}

Renderer::Renderer(GlContext& context, const PointCloud& cloud, std::optional<double> spacing,
                   std::size_t maxChunkPoints, PointMemory memory)
    : Renderer(context, cloud, estimatePointSpacing(cloud, spacing), maxChunkPoints, memory) {
    prepareNormals(cloud, NormalSource::Auto);
}

std::vector<glm::vec3> normalsFor(const PointCloud& cloud, NormalSource requested,
                                  const std::function<bool()>& cancelled) {
    const bool wanted =
        requested == NormalSource::Points ||
        (requested == NormalSource::Auto && cloud.size() <= kAlwaysEstimateNormalsPoints);
    return wanted && !cloud.hasNormals() ? estimateNormals(cloud, std::nullopt, cancelled)
                                         : std::vector<glm::vec3>();
}

void Renderer::prepareNormals(const PointCloud& cloud, NormalSource requested) {
    if (!cloud_.hasNormals()) {
        if (std::vector<glm::vec3> normals = normalsFor(cloud, requested); !normals.empty()) {
            setPointNormals(normals);
        }
    }
}

Renderer::Renderer(GlContext& context, const PointCloud& cloud, const PointSpacing& spacing,
                   std::size_t maxChunkPoints, PointMemory memory)
    : context_(context),
      clears_(sources_, context.capabilities()),
      maxChunkPoints_(maxChunkPoints),
      cloud_(cloud, context.capabilities(), maxChunkPoints, memory),
      spacing_(usableSpacing(cloud, spacing.global)),
      resolutionChooser_(cloud),
      cloudBounds_(cloud.bounds),
      reconstruction_(sources_, context.capabilities()),
      lightMaps_(context, sources_, clears_, reconstruction_) {
    if (!spacing.local.empty()) {
        setLocalSpacing(spacing.local);
    }
}

void Renderer::setLocalSpacing(const std::vector<glm::vec4>& spacing) {
    cloud_.setLocalSpacing(spacing);
    resolutionChooser_.setLocalSpacing(spacing);
}

Renderer::~Renderer() = default;

void Renderer::replaceCloud(const PointCloud& cloud, const PointSpacing& spacing,
                            PointMemory memory, const std::vector<glm::vec3>& normals) {
    replaceCloud(cloud, spacing, memory, packPointAttributes(spacing.local, normals));
}

void Renderer::replaceCloud(const PointCloud& cloud, const PointSpacing& spacing,
                            PointMemory memory, PackedPointAttributes packed) {
    replaceCloud(cloud, spacing, startUpload(cloud, memory, std::move(packed)));
}

GpuPointCloudUpload Renderer::startUpload(const PointCloud& cloud, PointMemory memory,
                                          PackedPointAttributes packed) const {
    return GpuPointCloudUpload(cloud, std::move(packed), context_.capabilities(), maxChunkPoints_,
                               memory);
}

void Renderer::replaceCloud(const PointCloud& cloud, const PointSpacing& spacing,
                            GpuPointCloudUpload upload) {
    // Everything that can fail (the uploads) first, on the side: a failure leaves the renderer
    // as it was, reading the old points.
    if (upload.size() != cloud.size()) {
        throw Error(fmt::format("an upload of {} points given for a cloud of {}", upload.size(),
                                cloud.size()));
    }
    GpuPointCloud uploaded = std::move(upload).take();
    ResolutionChooser chooser(cloud);
    if (!spacing.local.empty()) {
        chooser.setLocalSpacing(spacing.local);
    }
    cloud_ = std::move(uploaded);
    resolutionChooser_ = std::move(chooser);
    spacing_ = usableSpacing(cloud, spacing.global);
    cloudBounds_ = cloud.bounds;
    lightMaps_.forget();
    restartTemporalFilter();
}

RenderSettings Renderer::resolvedSettings(const RenderSettings& settings) const {
    RenderSettings resolved = settings;
    NormalSource& normals = resolved.surface.normals;
    if (normals != NormalSource::Screen) {
        normals = cloud_.hasNormals() ? NormalSource::Points : NormalSource::Screen;
    }
    // Without a local spacing the passes allocate none of its buffers.
    resolved.surface.localSpacing = settings.surface.localSpacing && cloud_.hasLocalSpacing();
    return resolved;
}

PresentPass& Renderer::present(const std::string& color, PresentBackground background,
                               const std::string& depth) {
    return lazyPass(presents_[{color, background, depth}], sources_, color, background, depth);
}

void Renderer::appendScattering(ScatteringMethod method, std::vector<RenderPass*>& passes) {
    switch (method) {
        case ScatteringMethod::Gaussian:
            passes.push_back(&lazyPass(subsurfaceScattering_, sources_));
            break;
        case ScatteringMethod::Single:
            passes.push_back(
                &lazyPass(singleScattering_, sources_, SingleScatteringBase::Radiance));
            break;
        case ScatteringMethod::Both:
            passes.push_back(&lazyPass(subsurfaceScattering_, sources_));
            passes.push_back(
                &lazyPass(singleAfterGaussian_, sources_, SingleScatteringBase::Scattered));
            break;
    }
}

void Renderer::appendPoints(RenderMode mode, std::vector<RenderPass*>& passes) {
    if (mode == RenderMode::PointsGl || mode == RenderMode::Splats) {
        passes.push_back(&lazyPass(drawPoints_, sources_));
    } else {
        reconstruction_.appendRasterization(passes);
    }
}

void Renderer::appendShading(bool split, std::vector<RenderPass*>& passes) {
    passes.push_back(split ? &lazyPass(shadeSplit_, sources_, ShadeOutputs::Split)
                           : &lazyPass(shade_, sources_, ShadeOutputs::Radiance));
}

void Renderer::appendPresent(const RenderSettings& settings, int divisor, const std::string& color,
                             std::vector<RenderPass*>& passes, TemporalDepth depth) {
    if (depth == TemporalDepth::SurfaceDepth) {
        passes.push_back(&lazyPass(outlineCoverages_[color], sources_, color));
    }
    if (!filtersTemporally(settings)) {
        passes.push_back(&present(color, PresentBackground::ByCoverage));
        return;
    }
    TemporalPass& temporal = lazyPass(temporal_, sources_, temporalHistory_);
    temporal.setInput(color, depth, divisor == 1);
    passes.push_back(&temporal);
    if (divisor != 1) {
        passes.push_back(&present("history", PresentBackground::InColor));
    }
}

void Renderer::restartTemporalFilter() {
    temporalHistory_.restart();
}

std::vector<RenderPass*> Renderer::passesFor(const RenderSettings& settings, int divisor,
                                             LevelZero levelZero) {
    const RasterSettings& raster = settings.raster;
    std::vector<RenderPass*> passes;
    appendPoints(raster.mode, passes);
    const bool stageView = !isFinalImage(raster.stage);
    const bool surface = reconstructsSurface(raster.mode);
    const bool scatters = raster.mode == RenderMode::Sss && raster.stage == Stage::Final;
    if (surface) {
        reconstruction_.appendSurface(passes, levelZero);
        if (levelZero == LevelZero::Fused) {
            if (!filtersTemporally(settings)) {
                passes.push_back(
                    &lazyPass(finishSurface_, sources_, FinishSurfacePass::Output::Picture));
                return passes;
            }
            // A moving camera's blend needs the neighbourhood: its own pass after this.
            if (temporalHistory_.modeFor(pipelineCamera_, settings, divisor) ==
                TemporalHistory::Mode::Moving) {
                passes.push_back(&lazyPass(finishSurfaceRadianceAndDepth_, sources_,
                                           FinishSurfacePass::Output::RadianceAndDepth));
                appendPresent(settings, divisor, "radianceAndDepth", passes,
                              TemporalDepth::ColorAlpha);
            } else {
                passes.push_back(&lazyPass(finishSurfaceTemporal_, sources_,
                                           FinishSurfacePass::Output::Temporal, &temporalHistory_));
            }
            return passes;
        }
        appendShading(scatters, passes);
    } else if (stageView && raster.stage != Stage::Depth) {
        throw Error(fmt::format("the stage '{}' exists only in the surface and sss modes",
                                toString(raster.stage)));
    }
    if (stageView) {
        passes.push_back(&lazyPass(stageViews_[raster.stage], sources_, raster.stage));
        passes.push_back(&present("stage", PresentBackground::InColor));
    } else if (scatters) {
        appendScattering(settings.scattering.method, passes);
        appendPresent(settings, divisor, "scatteredRadiance", passes);
    } else if (surface) {
        appendPresent(settings, divisor, "radiance", passes);
    } else {
        passes.push_back(&present("color", PresentBackground::WhereNoDepth, "depth"));
    }
    return passes;
}

FrameResult Renderer::render(const Camera& camera, const RenderSettings& requested,
                             FrameOutputs outputs) {
    const RenderSettings settings = resolvedSettings(requested);
    const int limit = capabilities().maxTextureSize;
    if (camera.width < 1 || camera.height < 1 || camera.width > limit || camera.height > limit) {
        throw Error(
            fmt::format("an image of {}x{} pixels is outside what the GPU can render "
                        "(1 to {} per side)",
                        camera.width, camera.height, limit));
    }
    if (!runner_ || runnerTiming_ != settings.raster.timing) {
        runner_ = std::make_unique<PassRunner>(context_, settings.raster.timing);
        runnerTiming_ = settings.raster.timing;
    }

    // The lights' views first: their maps are current before the camera's shading reads them.
    const bool lightMaps = usesLightMaps(settings);
    std::vector<PassTiming> lightTimings;
    if (lightMaps) {
        lightTimings =
            lightMaps_.update(cloud_, cloudBounds_, camera, settings, spacing_, *runner_);
    }

    // The point modes draw every pixel: at reduced resolution they would lose points.
    const int divisor =
        reconstructsSurface(settings.raster.mode)
            ? resolutionChooser_.divisor(settings.raster.resolution, camera, cloud_.origin(),
                                         spacing_, settings.surface.localSpacing)
            : 1;
    pipelineCamera_ = divisor == 1 ? camera : reducedCamera(camera, divisor);
    if (!filtersTemporally(settings)) {
        // Frames without the filter move on without it: its history no longer lines up.
        temporalHistory_.restart();
    } else {
        pipelineCamera_.jitterPixels +=
            temporalHistory_.nextJitter(pipelineCamera_, settings.temporal);
    }
    const gpu::PyramidLayout& layout =
        uniforms_.update(pipelineCamera_, settings, spacing_, cloud_);

    const bool fused =
        outputs == FrameOutputs::Picture && settings.raster.mode == RenderMode::Surface &&
        settings.raster.stage == Stage::Final && FinishSurfacePass::canFinish(divisor, layout);
    const std::vector<RenderPass*> passes =
        passesFor(settings, divisor, fused ? LevelZero::Fused : LevelZero::PerPass);
    lastDivisor_ = divisor;
    FrameContext context{pipelineCamera_,       cloud_,  settings, capabilities(),
                         resourcesFor(divisor), clears_, layout,   spacing_};
    context.cloudPixels = projectedPixelBounds(pipelineCamera_, cloudBounds_);
    context.outputs = outputs;
    context.lightMaps = lightMaps ? &lightMaps_ : nullptr;
    if (divisor != 1) {
        context.divisor = divisor;
        context.reducedFrom = glm::ivec2(camera.width, camera.height);
    }
    std::vector<PassTiming> timings = runner_->run(passes, context);
    timings.insert(timings.begin(), lightTimings.begin(), lightTimings.end());
    return {std::move(timings), divisor};
}

std::vector<std::uint8_t> Renderer::readImage() const {
    return resources().texture("image").readRgba8();
}

std::size_t Renderer::resourceBytes() const {
    return fullResources_.bytes() + reducedResources_.bytes() + lightMaps_.bytes();
}

}  // namespace subscan
