#include "render/FrameUniforms.h"

#include "core/Srgb.h"
#include "render/Pyramid.h"

namespace subscan {

const gpu::PyramidLayout& FrameUniforms::update(const Camera& camera,
                                                const RenderSettings& settings, double spacing,
                                                const GpuPointCloud& cloud) {
    gpu::FrameParams frame{};
    frame.viewFromCloud = glm::mat4(camera.viewFromCloud(cloud.origin()));
    frame.projection = glm::mat4(camera.projection());
    frame.viewport = {static_cast<float>(camera.width), static_cast<float>(camera.height),
                      1.0f / static_cast<float>(camera.width),
                      1.0f / static_cast<float>(camera.height)};
    frame.depthRange = {static_cast<float>(camera.nearPlane), static_cast<float>(camera.farPlane),
                        static_cast<float>(camera.focalLengthPixels()),
                        camera.orthographic() ? 1.0f : 0.0f};
    const glm::vec3& background = settings.raster.backgroundSrgb;
    frame.background = {srgbToLinear(background.r), srgbToLinear(background.g),
                        srgbToLinear(background.b), 1.0f};
    const glm::dvec2 shift = camera.pictureShiftPixels();
    frame.jitter = {static_cast<float>(shift.x), static_cast<float>(shift.y), 0.0f, 0.0f};
    frame_.set(frame);
    frame_.bind(SUBSCAN_UBO_FRAME);

    pyramid_ = pyramidLayout(camera.width, camera.height);
    pyramidBlock_.set(pyramid_);
    pyramidBlock_.bind(SUBSCAN_UBO_PYRAMID);

    const SurfaceSettings& surface = settings.surface;
    const auto h = static_cast<float>(spacing);
    gpu::SurfaceParams params{};
    params.visibility = {surface.visibilityRadius * h, surface.visibilityThreshold,
                         surface.edgeRule ? 1.0f : 0.0f, 0.0f};
    params.fill = {surface.fillRadius * h, static_cast<float>(surface.fillDirections),
                   surface.pullDepthSlope, placesOutlineBySubpixels(settings) ? 1.0f : 0.0f};
    params.normals = {surface.normalRadius * h, surface.outlineNormals ? 1.0f : 0.0f,
                      usesPointNormals(settings) ? 1.0f : 0.0f, 0.0f};
    params.spacing = {surface.localSpacing && cloud.hasLocalSpacing() ? 1.0f : 0.0f, 0.0f, 0.0f,
                      0.0f};
    surface_.set(params);
    surface_.bind(SUBSCAN_UBO_SURFACE);
    return pyramid_;
}

}  // namespace subscan
