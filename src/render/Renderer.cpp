#include "render/Renderer.h"

#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Spacing.h"
#include "render/DrawPointsPass.h"
#include "render/FillRemovalPass.h"
#include "render/HiddenPointRemovalPass.h"
#include "render/MinDepthPyramidPass.h"
#include "render/NormalsPass.h"
#include "render/PresentPass.h"
#include "render/PullPushPass.h"
#include "render/Pyramid.h"
#include "render/RasterizePointsPass.h"
#include "render/ShadePass.h"
#include "render/StageViewPass.h"

namespace subscan {

namespace {

/// h for the screen-space radii; a cloud without two distinct points still needs a scale.
double usableSpacing(const PointCloud& cloud, std::optional<double> spacing) {
    const double h = spacing.value_or(estimateSpacing(cloud));
    if (h > 0.0 && std::isfinite(h)) {
        return h;
    }
    const double diagonal = glm::length(cloud.bounds.extent());
    return diagonal > 0.0 ? 1e-3 * diagonal : 1e-3;
}

template <class Pass, class... Arguments>
Pass& cached(std::unique_ptr<Pass>& slot, Arguments&&... arguments) {
    if (!slot) {
        slot = std::make_unique<Pass>(std::forward<Arguments>(arguments)...);
    }
    return *slot;
}

}  // namespace

double FrameResult::totalMilliseconds() const {
    return std::accumulate(passes.begin(), passes.end(), 0.0,
                           [](double sum, const PassTiming& t) { return sum + t.milliseconds; });
}

float srgbToLinear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

Renderer::Renderer(GlContext& context, const PointCloud& cloud, std::optional<double> spacing,
                   std::size_t maxChunkPoints)
    : context_(context),
      cloud_(cloud, context.capabilities(), maxChunkPoints),
      spacing_(usableSpacing(cloud, spacing)) {}

Renderer::~Renderer() = default;

PresentPass& Renderer::present(const std::string& color, const std::string& depth) {
    return cached(presents_[{color, depth}], sources_, color, depth);
}

std::vector<RenderPass*> Renderer::passesFor(const RasterSettings& raster) {
    std::vector<RenderPass*> passes;
    if (raster.mode == RenderMode::PointsGl || raster.mode == RenderMode::Splats) {
        passes.push_back(&cached(drawPoints_, sources_));
    } else {
        passes.push_back(&cached(rasterize_, sources_, capabilities()));
    }
    const bool stageView = raster.stage != Stage::Final && raster.stage != Stage::Shaded;
    if (raster.mode == RenderMode::Surface) {
        passes.push_back(&cached(minDepthPyramid_, sources_));
        passes.push_back(&cached(hiddenPointRemoval_, sources_));
        passes.push_back(&cached(pullPush_, sources_));
        passes.push_back(&cached(fillRemoval_, sources_));
        passes.push_back(&cached(normals_, sources_));
        passes.push_back(&cached(shade_, sources_));
    } else if (stageView && raster.stage != Stage::Depth) {
        throw Error(
            fmt::format("the stage '{}' exists only in surface mode", toString(raster.stage)));
    }
    if (stageView) {
        passes.push_back(&cached(stageViews_[raster.stage], sources_, raster.stage));
        passes.push_back(&present("stage", ""));
    } else if (raster.mode == RenderMode::Surface) {
        passes.push_back(&present("radiance", "surfaceDepth"));
    } else {
        passes.push_back(&present("color", "depth"));
    }
    return passes;
}

FrameResult Renderer::render(const Camera& camera, const RenderSettings& settings) {
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

    gpu::FrameParams frame{};
    frame.viewFromCloud = glm::mat4(camera.viewFromCloud(cloud_.origin()));
    frame.projection = glm::mat4(camera.projection());
    frame.viewport = {static_cast<float>(camera.width), static_cast<float>(camera.height),
                      1.0f / static_cast<float>(camera.width),
                      1.0f / static_cast<float>(camera.height)};
    frame.depthRange = {static_cast<float>(camera.nearPlane), static_cast<float>(camera.farPlane),
                        static_cast<float>(camera.focalLengthPixels()), 0.0f};
    const glm::vec3& background = settings.raster.backgroundSrgb;
    frame.background = {srgbToLinear(background.r), srgbToLinear(background.g),
                        srgbToLinear(background.b), 1.0f};
    frameParams_.set(frame);
    frameParams_.bind(SUBSCAN_UBO_FRAME);

    const gpu::PyramidLayout layout = pyramidLayout(camera.width, camera.height);
    pyramidLayout_.set(layout);
    pyramidLayout_.bind(SUBSCAN_UBO_PYRAMID);

    const SurfaceSettings& surface = settings.surface;
    const auto h = static_cast<float>(spacing_);
    gpu::SurfaceParams surfaceParams{};
    surfaceParams.visibility = {surface.visibilityRadius * h, surface.visibilityThreshold,
                                surface.edgeRule ? 1.0f : 0.0f, 0.0f};
    surfaceParams.fill = {surface.fillRadius * h, surface.fillThreshold, 0.0f, 0.0f};
    surfaceParams.normals = {surface.normalRadius * h, 0.0f, 0.0f, 0.0f};
    surfaceParams_.set(surfaceParams);
    surfaceParams_.bind(SUBSCAN_UBO_SURFACE);

    const std::vector<RenderPass*> passes = passesFor(settings.raster);
    FrameContext context{camera, cloud_, settings, capabilities(), resources_, layout, spacing_};
    return {runner_->run(passes, context)};
}

std::vector<std::uint8_t> Renderer::readImage() const {
    return resources_.texture("image").readRgba8();
}

}  // namespace subscan
