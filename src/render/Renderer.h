#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/Camera.h"
#include "core/LocalSpacing.h"
#include "core/PointCloud.h"
#include "gpu/GlContext.h"
#include "gpu/PassTimer.h"
#include "gpu/ShaderSources.h"
#include "render/FrameResources.h"
#include "render/FrameUniforms.h"
#include "render/GpuPointCloud.h"
#include "render/LightMaps.h"
#include "render/PassRunner.h"
#include "render/PresentPass.h"
#include "render/Reconstruction.h"
#include "render/ReducedResolution.h"
#include "render/RenderSettings.h"
#include "render/TemporalPass.h"
#include "shared/bindings.h"

namespace subscan {

class RasterizePointsPass;
class DrawPointsPass;
class FinishSurfacePass;
class ShadePass;
class StageViewPass;
class SubsurfaceScatteringPass;
class SingleScatteringPass;
class OutlineCoveragePass;

/// The normals a renderer of `cloud` needs estimated (estimateNormals) for `requested`: where the
/// cloud has none of its own, for Points always, for Auto up to kAlwaysEstimateNormalsPoints
/// points; else none (empty). Seconds for millions of points: callers that make several
/// renderers of one cloud estimate once and give each setPointNormals.
/// `cancelled` as estimateNormals takes it.
std::vector<glm::vec3> normalsFor(const PointCloud& cloud, NormalSource requested,
                                  const std::function<bool()>& cancelled = {});

/// What a streamed view (the nodes a camera selects from a COPC file or EPT dataset) estimates
/// normals for, where `requested` was asked: `auto` estimates none there (screen-space normals,
/// unless the file has its own), since a view's million points took 4 of 6.7 s to estimate
/// (`render`, llvmpipe, 2 cores) and every new view would estimate again; `points` still does.
inline NormalSource streamedNormals(NormalSource requested) {
    return requested == NormalSource::Auto ? NormalSource::Screen : requested;
}

struct FrameResult {
    std::vector<PassTiming> passes;
    int divisor = 1;  // output pixels per pipeline pixel and side (RasterSettings::resolution)
    double totalMilliseconds() const;
};

/// The frame pipeline for one cloud: puts it on the GPU once, then renders frames for any
/// camera and settings with the passes of the chosen mode (and stage) followed by Present. The
/// same code serves the headless CLI, the viewer, the evaluation and the benchmark. Needs its
/// context current.
class Renderer {
  public:
    /// `spacing` overrides the estimated point spacing h; `maxChunkPoints` and `memory` see
    /// GpuPointCloud (PointMemory::Borrow: `cloud` outlives the renderer unchanged). The local
    /// spacing is estimated as estimatePointSpacing says, and normals as prepareNormals(cloud,
    /// NormalSource::Auto) says.
    Renderer(GlContext& context, const PointCloud& cloud,
             std::optional<double> spacing = std::nullopt, std::size_t maxChunkPoints = 0,
             PointMemory memory = PointMemory::Copy);
    /// With the spacing estimated beforehand (off the render thread); the cloud's own normals
    /// only, until setPointNormals() gives estimated ones.
    Renderer(GlContext& context, const PointCloud& cloud, const PointSpacing& spacing,
             std::size_t maxChunkPoints = 0, PointMemory memory = PointMemory::Copy);
    ~Renderer();

    /// Renders `cloud` from now on, as a renderer made for it with `spacing` would, keeping what
    /// does not depend on the points: the compiled passes and the images (the viewer's next
    /// set of a streamed survey's nodes shows a frame sooner, 0.1 s instead of 0.35 s on
    /// llvmpipe at 1280x720). The light maps are built again and the temporal filter starts
    /// afresh; normals are `normals` (setPointNormals' form) where given, else the cloud's own.
    /// On failure (the GPU cannot hold the points) it throws and keeps rendering the old cloud,
    /// which must then stay where it is.
    void replaceCloud(const PointCloud& cloud, const PointSpacing& spacing,
                      PointMemory memory = PointMemory::Copy,
                      const std::vector<glm::vec3>& normals = {});
    /// The same with `spacing.local` and the normals packed beforehand (packPointAttributes of
    /// that local spacing, which `packed` must hold), e.g. off the render thread, where the
    /// viewer packs them; no normals in `packed`: the cloud's own.
    void replaceCloud(const PointCloud& cloud, const PointSpacing& spacing, PointMemory memory,
                      PackedPointAttributes packed);
    /// An upload of `cloud` (with `packed`, as the overload above takes it) for this renderer's
    /// driver and chunks, which the caller advances a bounded number of bytes at a time (the
    /// viewer: a frame's worth) and then gives replaceCloud. Throws as replaceCloud does.
    GpuPointCloudUpload startUpload(const PointCloud& cloud, PointMemory memory,
                                    PackedPointAttributes packed) const;
    /// replaceCloud with the points of `upload` (startUpload's, for `cloud`): what it has not
    /// copied yet is copied now.
    void replaceCloud(const PointCloud& cloud, const PointSpacing& spacing,
                      GpuPointCloudUpload upload);

    /// Throws subscan::Error for impossible requests (image larger than the GPU allows, a
    /// forced raster path the driver lacks) and GL errors inside a pass.
    FrameResult render(const Camera& camera, const RenderSettings& settings,
                       FrameOutputs outputs = FrameOutputs::Picture);

    /// The last presented image: RGBA8, sRGB-encoded, row 0 at the top.
    std::vector<std::uint8_t> readImage() const;
    /// The last frame's images and buffers (see pipelineCamera()).
    const FrameResources& resources() const { return resourcesFor(lastDivisor_); }
    /// Bytes of every image and buffer the renderer holds, for the memory report.
    std::size_t resourceBytes() const;
    const GpuPointCloud& gpuCloud() const { return cloud_; }
    const GlCapabilities& capabilities() const { return context_.capabilities(); }
    double spacing() const { return spacing_; }
    /// Gives the cloud the local spacing `spacing` (estimateLocalSpacing's form, one entry per
    /// point) in place of the one the constructor estimated, or none.
    void setLocalSpacing(const std::vector<glm::vec4>& spacing);
    /// Gives the points normals (one per point, unit or 0 for none): NormalSource::Auto then
    /// uses them.
    void setPointNormals(const std::vector<glm::vec3>& normals) { cloud_.setNormals(normals); }
    /// Gives the renderer normalsFor(cloud, requested), `cloud` being the one it was made for,
    /// unless it has normals already.
    void prepareNormals(const PointCloud& cloud, NormalSource requested);
    /// `settings` with SurfaceSettings::normals resolved for this cloud: Auto becomes Points
    /// where the cloud has normals, else Screen, and so does Points without them (the passes
    /// see no Auto).
    RenderSettings resolvedSettings(const RenderSettings& settings) const;
    /// Replaces the points' colours (one per point, sRGB-encoded): another colouring.
    void setColors(const std::vector<Rgba8>& colors) { cloud_.setColors(colors); }
    /// The camera of the last frame's pipeline images (all but "image"): the frame's own
    /// camera, or reducedCamera(it, divisor) when it reconstructed at reduced resolution.
    const Camera& pipelineCamera() const { return pipelineCamera_; }
    /// Output pixels per pipeline pixel and side in the last frame (FrameResult::divisor).
    int pipelineDivisor() const { return lastDivisor_; }
    /// The compute rasterizer, once a frame has used it (null before).
    const RasterizePointsPass* rasterizePass() const { return reconstruction_.rasterizePass(); }
    /// The directional lights' maps (shadows), as the last frame that cast shadows left them.
    const LightMaps& lightMaps() const { return lightMaps_; }
    /// The temporal filter's next frame starts afresh instead of blending into the last (a cut).
    void restartTemporalFilter();

  private:
    /// The frame as named sub-pipelines: points -> reconstruction -> shading -> scattering ->
    /// temporal -> present (or a stage view).
    std::vector<RenderPass*> passesFor(const RenderSettings& settings, int divisor,
                                       LevelZero levelZero);
    /// The points as the mode draws them: compute-rasterized, or GL_POINTS for the baselines.
    void appendPoints(RenderMode mode, std::vector<RenderPass*>& passes);
    /// Deferred shading of the reconstructed surface, split into its parts for scattering.
    void appendShading(bool split, std::vector<RenderPass*>& passes);
    /// The scattering passes of the sss mode's final picture, by ScatteringSettings::method.
    void appendScattering(ScatteringMethod method, std::vector<RenderPass*>& passes);
    /// Present of the surface's linear colour `color` over the background by the share of each
    /// pixel the surface covers (OutlineCoveragePass, "mask"), through the temporal filter when
    /// the settings ask for it, which finds the depth where `depth` says (FinishSurface's
    /// "radianceAndDepth" holds the colour over the background already).
    void appendPresent(const RenderSettings& settings, int divisor, const std::string& color,
                       std::vector<RenderPass*>& passes,
                       TemporalDepth depth = TemporalDepth::SurfaceDepth);
    PresentPass& present(const std::string& color, PresentBackground background,
                         const std::string& depth = {});
    FrameResources& resourcesFor(int divisor) {
        return divisor == 1 ? fullResources_ : reducedResources_;
    }
    const FrameResources& resourcesFor(int divisor) const {
        return divisor == 1 ? fullResources_ : reducedResources_;
    }

    GlContext& context_;
    ShaderSources sources_;
    GpuClear clears_;
    std::size_t maxChunkPoints_;
    GpuPointCloud cloud_;
    double spacing_;
    ResolutionChooser resolutionChooser_;
    Bounds cloudBounds_;  // file coordinates
    Camera pipelineCamera_;
    int lastDivisor_ = 1;
    // One set per resolution, so that a camera crossing the Auto threshold does not reallocate
    // every image (a second on llvmpipe for 1080p) each time it crosses.
    FrameResources fullResources_;
    FrameResources reducedResources_;
    FrameUniforms uniforms_;
    Reconstruction reconstruction_;  // for the camera and the lights
    LightMaps lightMaps_;
    std::unique_ptr<DrawPointsPass> drawPoints_;
    std::unique_ptr<FinishSurfacePass> finishSurface_;
    std::unique_ptr<FinishSurfacePass> finishSurfaceRadianceAndDepth_;  // before TemporalPass
    std::unique_ptr<FinishSurfacePass> finishSurfaceTemporal_;          // with its blend at rest
    TemporalHistory temporalHistory_;
    std::unique_ptr<TemporalPass> temporal_;
    std::unique_ptr<ShadePass> shade_;
    std::unique_ptr<ShadePass> shadeSplit_;
    std::unique_ptr<SubsurfaceScatteringPass> subsurfaceScattering_;
    std::unique_ptr<SingleScatteringPass> singleScattering_;
    std::unique_ptr<SingleScatteringPass> singleAfterGaussian_;
    std::map<Stage, std::unique_ptr<StageViewPass>> stageViews_;
    std::map<std::tuple<std::string, PresentBackground, std::string>, std::unique_ptr<PresentPass>>
        presents_;
    std::map<std::string, std::unique_ptr<OutlineCoveragePass>> outlineCoverages_;  // by colour
    std::unique_ptr<PassRunner> runner_;
    TimingMode runnerTiming_ = TimingMode::Auto;
};

}  // namespace subscan
