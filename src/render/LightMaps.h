#pragma once

#include <cstddef>
#include <memory>
#include <string_view>
#include <vector>

#include "core/Camera.h"
#include "core/PointCloud.h"
#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"
#include "render/FrameResources.h"
#include "render/FrameUniforms.h"
#include "render/GpuPointCloud.h"
#include "render/LightMapPass.h"
#include "render/PassRunner.h"
#include "render/Reconstruction.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

/// A directional light's orthographic view of `bounds` (file coordinates), looking along
/// -towardsLight: `resolution` texels span the longer side of the box's projection — 0 chooses
/// one texel per point spacing h, within 64..2048 (the cap bounds what turning a light costs:
/// a build runs the reconstruction over every texel) — with kLightMapMargin empty texels on
/// every side (the filter's reach). Near and far hug the box.
Camera lightCamera(const Bounds& bounds, const glm::dvec3& towardsLight, int resolution,
                   double spacing);
inline constexpr int kLightMapMargin = 4;
/// What the names of a light map's passes begin with in a frame's timings.
inline constexpr std::string_view kLightMapPassPrefix = "LightMap.";

/// Whether a frame with these settings reads light maps: a final picture of the surface
/// modes with directional lights that cast shadows, whose single scattering finds its entries
/// in the maps (ScatteringSettings::lightPath), or that transmit light into the blur.
bool usesLightMaps(const RenderSettings& settings);
/// Whether the sss mode's shading adds the directional lights' light through thin parts to
/// the diffuse light its Gaussian blur spreads (ScatteringSettings::transmission).
bool transmitsLight(const RenderSettings& settings);

/// The reconstruction seen from each directional light (DESIGN.md §5.9): per light the
/// reconstruction of the cloud in the light's orthographic view, kept as its light map
/// (LightMapPass: depth along the light, +inf where it meets nothing, and normal). A map is
/// rebuilt only when its light or the settings that shape it (surface settings, raster path,
/// resolution) change; moving the camera costs nothing. All lights share one set of pipeline
/// images; each map keeps only its own texture.
class LightMaps {
  public:
    struct Map {
        Camera camera;    // the light's view, file coordinates
        Texture texture;  // RGBA32F (LightMapPass), row 0 at the top
    };

    LightMaps(GlContext& context, const ShaderSources& sources, GpuClear& clears,
              Reconstruction& reconstruction);

    /// Brings the maps up to date with `settings.shading` (one per directional light; those
    /// fixed to the view as `camera` turns them) and returns the timings of the passes that
    /// ran: empty when every map was current.
    std::vector<PassTiming> update(const GpuPointCloud& cloud, const Bounds& cloudBounds,
                                   const Camera& camera, const RenderSettings& settings,
                                   double spacing, PassRunner& runner);
    const std::vector<Map>& maps() const { return maps_; }
    /// The next update builds every map again: the cloud changed (Renderer::replaceCloud).
    void forget() {
        maps_.clear();
        keys_.clear();
    }
    /// Maps built so far (a light's first map counts): for tests of the caching.
    std::size_t builds() const { return builds_; }
    /// Bytes of the maps and of the pipeline images they are built in.
    std::size_t bytes() const;

    /// The light-map parameters of ShadeParams for a frame seen by `camera` (shadows as
    /// `settings` say), and the maps bound to their texture units (SUBSCAN_TEXTURES_LIGHT_MAPS
    /// + light).
    void prepareShading(gpu::ShadeParams& params, const Camera& camera,
                        const ShadingSettings& settings, double spacing) const;

  private:
    /// What a map depends on besides the cloud.
    struct Key {
        glm::dvec3 towardsLight{0.0};
        int resolution = 0;
        SurfaceSettings surface;
        RasterPath path = RasterPath::Auto;
        float normalBlend = 0.0f;  // the normals a map keeps
        bool operator==(const Key&) const = default;
    };

    GlContext& context_;
    const ShaderSources& sources_;
    GpuClear& clears_;
    Reconstruction& reconstruction_;
    FrameResources resources_;  // the pipeline images of the map being built
    FrameUniforms uniforms_;
    std::unique_ptr<LightMapPass> pack_;
    std::vector<Map> maps_;
    std::vector<Key> keys_;
    std::size_t builds_ = 0;
};

}  // namespace subscan
