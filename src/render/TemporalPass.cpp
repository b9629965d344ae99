#include "render/TemporalPass.h"

#include <algorithm>
#include <limits>
#include <vector>

#include <glm/matrix.hpp>

#include "core/Srgb.h"
#include "render/PresentPass.h"

namespace subscan {

namespace {

/// The history saw another surface where the depth it kept differs from the reprojected one by
/// more than this many point spacings (plus the depth range of the pixel's neighbourhood, for
/// surfaces seen at a grazing angle): a point of the same surface lands within about h of
/// where the previous frame's reconstruction put it.
constexpr double kDisocclusionSpacings = 4.0;

double radicalInverse(unsigned index, unsigned base) {
    double result = 0.0;
    double digitWeight = 1.0 / base;
    for (; index > 0; index /= base) {
        result += (index % base) * digitWeight;
        digitWeight /= base;
    }
    return result;
}

/// Same image, same lens, same pose: the previous result lines up with this frame's pixels.
bool sameView(const Camera& a, const Camera& b) {
    return a.width == b.width && a.height == b.height && a.fovyDegrees == b.fovyDegrees &&
           a.nearPlane == b.nearPlane && a.farPlane == b.farPlane && a.view == b.view &&
           a.orthographicHeight == b.orthographicHeight &&
           a.principalOffsetPixels == b.principalOffsetPixels;
}

Camera withoutJitter(const Camera& camera) {
    Camera plain = camera;
    plain.jitterPixels = glm::dvec2(0.0);
    return plain;
}

}  // namespace

glm::dvec2 haltonJitter(unsigned index) {
    return {radicalInverse(index, 2) - 0.5, radicalInverse(index, 3) - 0.5};
}

glm::dvec2 TemporalHistory::nextJitter(const Camera& camera, const TemporalSettings& settings) {
    if (!previous_ || !sameView(previous_->camera, camera)) {
        frameIndex_ = 0;
        if (previous_) {
            return glm::dvec2(0.0);
        }
    }
    const unsigned index = frameIndex_ % static_cast<unsigned>(settings.maxFrames) + 1;
    ++frameIndex_;
    return haltonJitter(index);
}

TemporalHistory::Mode TemporalHistory::modeFor(const Camera& camera, const RenderSettings& settings,
                                               int divisor) const {
    const bool continues =
        previous_ && previous_->settings == settings && previous_->divisor == divisor &&
        previous_->camera.width == camera.width && previous_->camera.height == camera.height;
    if (!continues) {
        return Mode::Restart;
    }
    return sameView(previous_->camera, withoutJitter(camera)) ? Mode::Still : Mode::Moving;
}

TemporalHistory::Mode TemporalHistory::begin(FrameContext& frame, bool picture) {
    FrameResources& resources = frame.resources;
    const int width = frame.width(), height = frame.height();
    const Camera camera = withoutJitter(frame.camera);
    for (const char* name : {"history", "previousHistory"}) {
        resources.ensureTexture(name, TextureFormat::RGBA32F, width, height);
    }
    for (const char* name : {"historyState", "previousHistoryState"}) {
        resources.ensureTexture(name, TextureFormat::RG32F, width, height);
    }
    resources.swapTextures("history", "previousHistory");
    resources.swapTextures("historyState", "previousHistoryState");

    const Mode mode = modeFor(frame.camera, frame.settings, frame.divisor);
    gpu::TemporalParams params{};
    params.flags.x = previous_ && previous_->moved ? 1u : 0u;
    if (mode != Mode::Restart) {
        params.previousFromView = glm::mat4(previous_->camera.view * glm::inverse(camera.view));
        params.previousProjection = glm::mat4(previous_->camera.projection());
    }
    const TemporalSettings& settings = frame.settings.temporal;
    params.blend = {settings.newFrameWeight, settings.clipSigma,
                    static_cast<float>(settings.maxFrames), 0.0f};
    params.depth = {static_cast<float>(kDisocclusionSpacings * frame.spacing), 0.0f, 0.0f, 0.0f};
    params_.set(params);
    params_.bind(SUBSCAN_UBO_TEMPORAL);

    Texture& history = resources.texture("history");
    Texture& state = resources.texture("historyState");
    Texture* image =
        picture ? &resources.ensureTexture("image", TextureFormat::RGBA8, width, height) : nullptr;
    const TexelRegion region = frame.region(0);
    if (mode == Mode::Restart) {
        writtenBefore_.reset();
        writtenLast_.reset();
    }
    if (region.size != glm::ivec2(width, height)) {
        // Off the region this frame shows the background (surfaceDepth is +inf there). The
        // history images hold it already except where they held an earlier frame: a full clear
        // of them costs more than the filter itself (RGBA32F; bench/README, "On a GPU").
        const glm::vec3& background = frame.settings.raster.backgroundSrgb;
        const glm::vec4 backgroundHistory(srgbToLinear(background.r), srgbToLinear(background.g),
                                          srgbToLinear(background.b), 0.0f);
        const glm::vec4 backgroundState(std::numeric_limits<float>::infinity(), 1.0f, 0.0f, 0.0f);
        const std::vector<TexelRegion> stale =
            writtenBefore_ ? texelsOutside(*writtenBefore_, region)
                           : std::vector<TexelRegion>{{glm::ivec2(0), glm::ivec2(width, height)}};
        for (const TexelRegion& part : stale) {
            frame.clear(history, part, backgroundHistory);
            frame.clear(state, part, backgroundState);
        }
        if (image) {
            PresentPass::clearToBackground(frame, *image);
        }
    }
    if (image) {
        image->bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    }
    resources.texture("previousHistory").bindImage(SUBSCAN_IMAGE_IN2, GL_READ_ONLY);
    resources.texture("previousHistoryState").bindImage(SUBSCAN_IMAGE_IN3, GL_READ_ONLY);
    history.bindImage(SUBSCAN_IMAGE_OUT2, GL_WRITE_ONLY);
    state.bindImage(SUBSCAN_IMAGE_OUT3, GL_WRITE_ONLY);
    return mode;
}

void TemporalHistory::end(const FrameContext& frame, Mode mode) {
    writtenBefore_ = writtenLast_;
    writtenLast_ = frame.region(0);
    previous_ = PreviousFrame{withoutJitter(frame.camera), frame.settings, frame.divisor,
                              mode == Mode::Moving};
}

TemporalPass::TemporalPass(const ShaderSources& sources, TemporalHistory& history)
    : sources_(sources), history_(history) {}

std::vector<std::string_view> TemporalPass::inputs(const RenderSettings&) const {
    if (depth_ == TemporalDepth::ColorAlpha) {
        return {colorInput_};
    }
    return {colorInput_, "surfaceDepth"};
}

std::vector<std::string_view> TemporalPass::outputs(const RenderSettings&) const {
    if (writesPicture_) {
        return {"history", "historyState", "image"};
    }
    return {"history", "historyState"};
}

const ComputeStages& TemporalPass::stages() {
    const bool inAlpha = depth_ == TemporalDepth::ColorAlpha;
    std::optional<ComputeStages>& stages = stages_[inAlpha ? 1 : 0];
    if (!stages) {
        stages.emplace(sources_, "render/Temporal.comp",
                       std::vector<std::string>{"RESTART", "STILL", "MOVING", "RESTART_PICTURE",
                                                "STILL_PICTURE", "MOVING_PICTURE"},
                       inAlpha ? "#define TEMPORAL_DEPTH_IN_ALPHA 1\n"
                               : "#define TEMPORAL_DEPTH_IN_ALPHA 0\n");
    }
    return *stages;
}

void TemporalPass::execute(FrameContext& frame) {
    const ComputeStages& variants = stages();
    const TemporalHistory::Mode mode = history_.begin(frame, writesPicture_);
    frame.resources.texture(colorInput_).bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    if (depth_ == TemporalDepth::SurfaceDepth) {
        frame.resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    }
    variants.runOverRegion(static_cast<std::size_t>(mode) + (writesPicture_ ? 3 : 0),
                           frame.region(0));
    glMemoryBarrier(kImageWritesBarrier);
    history_.end(frame, mode);
}

}  // namespace subscan
