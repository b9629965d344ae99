#include "render/LightMaps.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/Error.h"

namespace subscan {

namespace {

constexpr int kAutoMinResolution = 64;
constexpr int kAutoMaxResolution = 2048;

}  // namespace

bool usesLightMaps(const RenderSettings& settings) {
    const RasterSettings& raster = settings.raster;
    if (!reconstructsSurface(raster.mode) || !isFinalImage(raster.stage) ||
        settings.shading.lights.empty()) {
        return false;
    }
    const ScatteringSettings& scattering = settings.scattering;
    const bool singleFromMaps = raster.mode == RenderMode::Sss && raster.stage == Stage::Final &&
                                scattering.method != ScatteringMethod::Gaussian &&
                                scattering.lightPath == LightPath::LightMap;
    return settings.shading.shadows || singleFromMaps || transmitsLight(settings);
}

bool transmitsLight(const RenderSettings& settings) {
    return settings.raster.mode == RenderMode::Sss && isFinalImage(settings.raster.stage) &&
           settings.scattering.method != ScatteringMethod::Single &&
           settings.scattering.transmission && !settings.shading.lights.empty();
}

Camera lightCamera(const Bounds& bounds, const glm::dvec3& towardsLight, int resolution,
                   double spacing) {
    const glm::dvec3 direction = glm::normalize(towardsLight);
    const glm::dvec3 centre = bounds.center();
    const double radius = std::max(0.5 * glm::length(bounds.extent()), spacing);
    // Any up vector not along the light will do: the map is sampled through its matrices.
    const glm::dvec3 up =
        std::abs(direction.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    const double eyeDistance = 2.0 * radius;
    glm::dmat4 view = glm::lookAt(centre + eyeDistance * direction, centre, up);

    glm::dvec3 low(std::numeric_limits<double>::infinity());
    glm::dvec3 high(-std::numeric_limits<double>::infinity());
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p = bounds.corner(corner);
        const glm::dvec3 v(view * glm::dvec4(p, 1.0));
        low = glm::min(low, v);
        high = glm::max(high, v);
    }
    // Centre the box's projection on the view axis.
    const glm::dvec2 middle = 0.5 * (glm::dvec2(low) + glm::dvec2(high));
    view = glm::translate(glm::dmat4(1.0), glm::dvec3(-middle, 0.0)) * view;
    const glm::dvec2 extent = glm::max(glm::dvec2(high) - glm::dvec2(low), glm::dvec2(spacing));
    const double longer = std::max(extent.x, extent.y);
    if (resolution == 0) {
        resolution = std::clamp(static_cast<int>(std::ceil(longer / spacing)), kAutoMinResolution,
                                kAutoMaxResolution);
    }
    const double texel = longer / resolution;
    Camera camera;
    camera.view = view;
    // Whole texels; the slack keeps an extent of exactly `resolution` texels from rounding up.
    const auto texels = [&](double length) {
        return std::max(1, static_cast<int>(std::ceil(length / texel - 1e-6)));
    };
    camera.width = texels(extent.x) + 2 * kLightMapMargin;
    camera.height = texels(extent.y) + 2 * kLightMapMargin;
    camera.orthographicHeight = camera.height * texel;
    // Depths are -z; a margin of a few texels keeps the box's own corners inside.
    const double depthMargin = 4.0 * texel;
    camera.nearPlane = std::max(-high.z - depthMargin, 0.5 * (-high.z));
    camera.farPlane = -low.z + depthMargin;
    return camera;
}

LightMaps::LightMaps(GlContext& context, const ShaderSources& sources, GpuClear& clears,
                     Reconstruction& reconstruction)
    : context_(context), sources_(sources), clears_(clears), reconstruction_(reconstruction) {}

std::vector<PassTiming> LightMaps::update(const GpuPointCloud& cloud, const Bounds& cloudBounds,
                                          const Camera& camera, const RenderSettings& settings,
                                          double spacing, PassRunner& runner) {
    const std::vector<DirectionalLight>& lights = settings.shading.lights;
    const std::size_t count = std::min<std::size_t>(lights.size(), SUBSCAN_MAX_LIGHTS);
    maps_.resize(count);
    keys_.resize(count);
    // The light's view reconstructs the surface like the camera's, without intermediate stages.
    RenderSettings lightSettings = settings;
    lightSettings.raster.mode = RenderMode::Surface;
    lightSettings.raster.stage = Stage::Final;
    lightSettings.raster.resolution = Resolution::Full;

    std::vector<PassTiming> timings;
    for (std::size_t i = 0; i < count; ++i) {
        const Key key{towardsLightInWorld(lights[i], camera.view),
                      settings.shading.lightMapResolution, settings.surface, settings.raster.path,
                      settings.raster.normalBlend};
        if (maps_[i].texture.id() != 0 && keys_[i] == key) {
            continue;
        }
        const Camera view = lightCamera(cloudBounds, key.towardsLight, key.resolution, spacing);
        const int limit = context_.capabilities().maxTextureSize;
        if (view.width > limit || view.height > limit) {
            throw Error(
                fmt::format("a light map of {}x{} texels is larger than the GPU allows "
                            "({} per side): lower 'light_map_resolution'",
                            view.width, view.height, limit));
        }
        const gpu::PyramidLayout& layout = uniforms_.update(view, lightSettings, spacing, cloud);
        FrameContext frame{view,       cloud,   lightSettings, context_.capabilities(),
                           resources_, clears_, layout,        spacing};
        frame.cloudPixels = projectedPixelBounds(view, cloudBounds);
        std::vector<RenderPass*> passes;
        reconstruction_.appendAll(passes);
        passes.push_back(&lazyPass(pack_, sources_));
        for (PassTiming& timing : runner.run(passes, frame)) {
            timing.pass = std::string(kLightMapPassPrefix) + timing.pass;
            timings.push_back(std::move(timing));
        }

        Map& map = maps_[i];
        if (map.texture.width() != view.width || map.texture.height() != view.height) {
            map.texture =
                Texture(TextureFormat::RGBA32F, view.width, view.height, "LightMap.texture");
        }
        glCopyImageSubData(resources_.texture("lightMap").id(), GL_TEXTURE_2D, 0, 0, 0, 0,
                           map.texture.id(), GL_TEXTURE_2D, 0, 0, 0, 0, view.width, view.height, 1);
        map.camera = view;
        keys_[i] = key;
        ++builds_;
    }
    return timings;
}

std::size_t LightMaps::bytes() const {
    std::size_t total = resources_.bytes();
    for (const Map& map : maps_) {
        total += static_cast<std::size_t>(map.texture.width()) * map.texture.height() * 4 *
                 sizeof(float);
    }
    return total;
}

void LightMaps::prepareShading(gpu::ShadeParams& params, const Camera& camera,
                               const ShadingSettings& settings, double spacing) const {
    const glm::dmat4 worldFromView = glm::inverse(camera.view);
    const std::size_t count = std::min<std::size_t>(maps_.size(), params.lightCount.x);
    for (std::size_t i = 0; i < count; ++i) {
        const Map& map = maps_[i];
        params.lightFromView[i] = glm::mat4(map.camera.view * worldFromView);
        params.lightMap[i] = {static_cast<float>(map.camera.focalLengthPixels()),
                              static_cast<float>(map.camera.width),
                              static_cast<float>(map.camera.height),
                              settings.shadows ? 1.0f : 0.0f};
        map.texture.bindSampler(SUBSCAN_TEXTURES_LIGHT_MAPS + static_cast<GLuint>(i));
    }
    params.shadow = {static_cast<float>(settings.shadowBias * spacing),
                     static_cast<float>(settings.shadowSoftness * spacing), 0.0f, 0.0f};
}

}  // namespace subscan
