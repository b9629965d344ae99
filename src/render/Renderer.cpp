#include "render/Renderer.h"

#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

double FrameResult::totalMilliseconds() const {
    return std::accumulate(passes.begin(), passes.end(), 0.0,
                           [](double sum, const PassTiming& t) { return sum + t.milliseconds; });
}

float srgbToLinear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

Renderer::Renderer(GlContext& context, const PointCloud& cloud, std::size_t maxChunkPoints)
    : context_(context), cloud_(cloud, context.capabilities(), maxChunkPoints) {}

std::vector<RenderPass*> Renderer::passesFor(RenderMode mode) {
    std::vector<RenderPass*> passes;
    switch (mode) {
        case RenderMode::Points:
            if (!rasterize_) {
                rasterize_ = std::make_unique<RasterizePointsPass>(sources_, capabilities());
            }
            passes.push_back(rasterize_.get());
            break;
        case RenderMode::PointsGl:
        case RenderMode::Splats:
            if (!drawPoints_) {
                drawPoints_ = std::make_unique<DrawPointsPass>(sources_);
            }
            passes.push_back(drawPoints_.get());
            break;
    }
    if (!present_) {
        present_ = std::make_unique<PresentPass>(sources_);
    }
    passes.push_back(present_.get());
    return passes;
}

FrameResult Renderer::render(const Camera& camera, const RasterSettings& settings) {
    const int limit = capabilities().maxTextureSize;
    if (camera.width < 1 || camera.height < 1 || camera.width > limit || camera.height > limit) {
        throw Error(
            fmt::format("an image of {}x{} pixels is outside what the GPU can render "
                        "(1 to {} per side)",
                        camera.width, camera.height, limit));
    }
    if (!runner_ || runnerTiming_ != settings.timing) {
        runner_ = std::make_unique<PassRunner>(context_, settings.timing);
        runnerTiming_ = settings.timing;
    }

    gpu::FrameParams params{};
    params.viewFromCloud = glm::mat4(camera.viewFromCloud(cloud_.origin()));
    params.projection = glm::mat4(camera.projection());
    params.viewport = {static_cast<float>(camera.width), static_cast<float>(camera.height),
                       1.0f / static_cast<float>(camera.width),
                       1.0f / static_cast<float>(camera.height)};
    params.depthRange = {static_cast<float>(camera.nearPlane), static_cast<float>(camera.farPlane),
                         static_cast<float>(camera.focalLengthPixels()), 0.0f};
    params.background = {srgbToLinear(settings.backgroundSrgb.r),
                         srgbToLinear(settings.backgroundSrgb.g),
                         srgbToLinear(settings.backgroundSrgb.b), 1.0f};
    frameParams_.set(params);
    frameParams_.bind(SUBSCAN_UBO_FRAME);

    const std::vector<RenderPass*> passes = passesFor(settings.mode);
    FrameContext frame{camera, cloud_, settings, capabilities(), resources_};
    return {runner_->run(passes, frame)};
}

std::vector<std::uint8_t> Renderer::readImage() const {
    return resources_.texture("image").readRgba8();
}

}  // namespace subscan
