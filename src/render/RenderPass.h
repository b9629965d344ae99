#pragma once

#include <memory>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "core/Camera.h"
#include "gpu/GlContext.h"
#include "gpu/GpuClear.h"
#include "render/ComputeStages.h"
#include "render/FrameResources.h"
#include "render/GpuPointCloud.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

class LightMaps;

/// What a frame must leave in Renderer::resources(): the picture ("image", and in the surface
/// modes "surfaceDepth", which the viewer picks the orbit centre from), or every image its
/// passes write (exports, evaluation, tests of the passes). The surface mode's final
/// full-resolution frames finish in one dispatch for the picture alone (FinishSurfacePass), and
/// SingleScatteringPass leaves its term and coefficients out; the images skipped then still
/// hold an earlier frame, if any.
enum class FrameOutputs { Picture, Everything };

/// Everything a pass may use while it runs. The frame-wide uniform blocks (FrameParams,
/// PyramidLayout, SurfaceParams) are already bound.
struct FrameContext {
    const Camera& camera;
    const GpuPointCloud& cloud;
    const RenderSettings& settings;
    const GlCapabilities& capabilities;
    FrameResources& resources;
    GpuClear& clears;
    const gpu::PyramidLayout& pyramid;
    double spacing;  // the point spacing h, scene units
    /// Pixels [x, y, z, w) holding rasterized points, and those beyond them a sparse surface's
    /// fill may reach (MinDepthPyramidPass), measured when
    /// `surfaceBoundsAllowed(settings)`; unset, the passes after it work on the whole frame.
    std::optional<glm::ivec4> pointBounds;
    /// At reduced resolution (RasterSettings::resolution) `camera` is reducedCamera(the
    /// output's camera, divisor) and Present scales up to the output's size.
    int divisor = 1;
    std::optional<glm::ivec2> reducedFrom;  // the output's size; unset at full resolution
    /// Pixels [x, y, z, w) the cloud's bounding box projects to (projectedPixelBounds): no
    /// point lands outside them. Unset: anywhere in the image.
    std::optional<glm::ivec4> cloudPixels;
    FrameOutputs outputs = FrameOutputs::Everything;
    /// The directional lights' maps, current for this frame's settings; null: no shadows.
    const LightMaps* lightMaps = nullptr;

    /// Clears by the path the settings name (GpuClear).
    void clear(Texture& texture, const glm::vec4& value = glm::vec4(0.0f)) const {
        clears.texture(texture, value, settings.raster.clears);
    }
    void clear(Texture& texture, const TexelRegion& region, const glm::vec4& value) const {
        clears.textureRegion(texture, region.origin, region.size, value, settings.raster.clears);
    }
    void clearUint(Texture& texture, std::uint32_t value) const {
        clears.textureUint(texture, value, settings.raster.clears);
    }
    void fill(Buffer& buffer, std::uint32_t value) const {
        clears.buffer(buffer, value, settings.raster.clears);
    }
    /// The frame-sized image `name` a pass writes over its region only: where the frame is
    /// restricted to the points' bounds it is first cleared to `outside`, so that nothing an
    /// earlier frame left there is read as this frame's.
    Texture& imageOverRegion(std::string_view name, TextureFormat format,
                             const glm::vec4& outside = glm::vec4(0.0f)) const;
    /// The same for an image read no further than `ring` texels off the region: only that ring
    /// is cleared (a whole RGBA32F image costs llvmpipe about 1.6 ms at 1280x720).
    Texture& imageOverRegion(std::string_view name, TextureFormat format, int ring,
                             const glm::vec4& outside) const;

    int width() const { return camera.width; }
    int height() const { return camera.height; }
    bool restricted() const { return pointBounds.has_value(); }
    /// cloudPixels as a region of the image.
    TexelRegion cloudRegion() const;
    glm::ivec2 outputSize() const { return reducedFrom.value_or(glm::ivec2(width(), height())); }
    /// The texels of pyramid `level` (0: the image) a pass must compute: those around the
    /// points, with a margin for the 4x4 pull and the bilinear push and normal reads.
    TexelRegion region(unsigned level) const;
};

/// Between the levels of a pyramid pass: storage-buffer writes become visible to the next
/// dispatch's storage-buffer and buffer-texture reads (Buffer::bindTexels).
constexpr GLbitfield kPyramidWritesBarrier =
    GL_SHADER_STORAGE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT;

/// After a dispatch's image writes, before anything reads them: image loads, texture fetches,
/// or texture uploads and downloads.
constexpr GLbitfield kImageWritesBarrier = GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                                           GL_TEXTURE_FETCH_BARRIER_BIT |
                                           GL_TEXTURE_UPDATE_BARRIER_BIT;

/// Who computes the full-resolution level of the surface pipeline (push, mask, normals, shading,
/// encoding): each pass its own (PerPass: every intermediate image exists, for stage views,
/// exports, scattering and evaluation), or FinishSurfacePass in one dispatch (Fused:
/// PullPushPass, FillRemovalPass and NormalsPass stop above level 0).
enum class LevelZero { PerPass, Fused };

/// Whether the passes after rasterization may skip the screen outside the points' bounds: when
/// no pixel there can become surface (fill removal needs 6 or more of the 8 directions, and a
/// pixel beside the bounds finds points in at most 5) and the frame shows no intermediate
/// stage (those show pull-push's fill of the whole screen).
bool surfaceBoundsAllowed(const RenderSettings& settings);

/// One step of the frame pipeline: one class and one shader of the same name (Falcor's
/// RenderPass). It declares the images and buffers it reads and writes in a frame of
/// `settings` by name so the runner can check the wiring, time it and dump any of its outputs.
class RenderPass {
  public:
    virtual ~RenderPass() = default;
    virtual std::string_view name() const = 0;
    virtual std::vector<std::string_view> inputs(const RenderSettings& settings) const = 0;
    virtual std::vector<std::string_view> outputs(const RenderSettings& settings) const = 0;
    virtual void execute(FrameContext& frame) = 0;
};

/// The pass in `slot`, built from `arguments` on first use: a frame compiles the shaders of
/// the passes it runs, not of every mode.
template <class Pass, class... Arguments>
Pass& lazyPass(std::unique_ptr<Pass>& slot, Arguments&&... arguments) {
    if (!slot) {
        slot = std::make_unique<Pass>(std::forward<Arguments>(arguments)...);
    }
    return *slot;
}

}  // namespace subscan
