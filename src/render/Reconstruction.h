#pragma once

#include <memory>
#include <vector>

#include "gpu/GlContext.h"
#include "gpu/ShaderSources.h"
#include "render/RenderPass.h"

namespace subscan {

class RasterizePointsPass;
class MinDepthPyramidPass;
class HiddenPointRemovalPass;
class PullPushPass;
class FillRemovalPass;
class NormalsPass;

/// The screen-space reconstruction (DESIGN.md §5 steps 1-5) as one unit for any view: the
/// camera's (Renderer) or a directional light's orthographic one (LightMaps). Its passes keep
/// nothing of a view between runs — every image lives in the view's FrameResources — so one
/// set of compiled shaders serves all views. Passes are built on first use.
class Reconstruction {
  public:
    Reconstruction(const ShaderSources& sources, const GlCapabilities& capabilities);
    ~Reconstruction();
    Reconstruction(const Reconstruction&) = delete;
    Reconstruction& operator=(const Reconstruction&) = delete;

    /// Step 1: the compute rasterizer's 1-pixel points ("depth", "color").
    void appendRasterization(std::vector<RenderPass*>& passes);
    /// Steps 2-5 on the rasterized points. With LevelZero::Fused the full-resolution level is
    /// left to FinishSurfacePass.
    void appendSurface(std::vector<RenderPass*>& passes, LevelZero levelZero);
    /// Both, every level, for a view that needs only the surface (a light's).
    void appendAll(std::vector<RenderPass*>& passes);

    /// The compute rasterizer, once a frame has used it (null before).
    const RasterizePointsPass* rasterizePass() const { return rasterize_.get(); }

  private:
    const ShaderSources& sources_;
    const GlCapabilities& capabilities_;
    std::unique_ptr<RasterizePointsPass> rasterize_;
    std::unique_ptr<MinDepthPyramidPass> minDepthPyramid_;
    std::unique_ptr<HiddenPointRemovalPass> hiddenPointRemoval_;
    std::unique_ptr<PullPushPass> pullPush_;
    std::unique_ptr<FillRemovalPass> fillRemoval_;
    std::unique_ptr<NormalsPass> normals_;
};

}  // namespace subscan
