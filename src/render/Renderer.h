#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/Camera.h"
#include "core/PointCloud.h"
#include "gpu/GlContext.h"
#include "gpu/PassTimer.h"
#include "gpu/ShaderSources.h"
#include "render/DrawPointsPass.h"
#include "render/FrameResources.h"
#include "render/GpuPointCloud.h"
#include "render/PassRunner.h"
#include "render/PresentPass.h"
#include "render/RasterizePointsPass.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

struct FrameResult {
    std::vector<PassTiming> passes;
    double totalMilliseconds() const;
};

/// The frame pipeline for one cloud: uploads it once, then renders frames for any camera and
/// settings with the passes of the chosen mode followed by Present. The same code serves the
/// headless CLI, the viewer and the benchmark. Needs its context current.
class Renderer {
  public:
    /// `maxChunkPoints`: see GpuPointCloud (tests force small chunks).
    Renderer(GlContext& context, const PointCloud& cloud, std::size_t maxChunkPoints = 0);

    /// Throws subscan::Error for impossible requests (image larger than the GPU allows, a
    /// forced raster path the driver lacks) and GL errors inside a pass.
    FrameResult render(const Camera& camera, const RasterSettings& settings);

    /// The last presented image: RGBA8, sRGB-encoded, row 0 at the top.
    std::vector<std::uint8_t> readImage() const;
    const FrameResources& resources() const { return resources_; }
    const GpuPointCloud& gpuCloud() const { return cloud_; }
    const GlCapabilities& capabilities() const { return context_.capabilities(); }
    /// The compute rasterizer, once a Points frame has been rendered (null before).
    const RasterizePointsPass* rasterizePass() const { return rasterize_.get(); }

  private:
    std::vector<RenderPass*> passesFor(RenderMode mode);

    GlContext& context_;
    ShaderSources sources_;
    GpuPointCloud cloud_;
    FrameResources resources_;
    UniformBlock<gpu::FrameParams> frameParams_{"FrameParams"};
    std::unique_ptr<RasterizePointsPass> rasterize_;
    std::unique_ptr<DrawPointsPass> drawPoints_;
    std::unique_ptr<PresentPass> present_;
    std::unique_ptr<PassRunner> runner_;
    TimingMode runnerTiming_ = TimingMode::Auto;
};

/// sRGB-encoded 0..1 -> linear, the CPU twin of srgbToLinear in shaders/shared/common.glsl.
float srgbToLinear(float encoded);

}  // namespace subscan
