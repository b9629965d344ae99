#pragma once

#include "core/Camera.h"
#include "gpu/GlObjects.h"
#include "render/GpuPointCloud.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

/// The frame-wide uniform blocks every pass may read: the camera (FrameParams), the pyramid
/// layout for the image size and the reconstruction radii (SurfaceParams, radii = settings x h;
/// the passes scale them by the local spacing where `cloud` carries it and the settings use it).
/// update() fills and binds them; the Renderer calls it once per frame, tests before running a
/// single pass.
class FrameUniforms {
  public:
    const gpu::PyramidLayout& update(const Camera& camera, const RenderSettings& settings,
                                     double spacing, const GpuPointCloud& cloud);
    const gpu::PyramidLayout& pyramid() const { return pyramid_; }

  private:
    UniformBlock<gpu::FrameParams> frame_{"FrameParams"};
    UniformBlock<gpu::PyramidLayout> pyramidBlock_{"PyramidLayout"};
    UniformBlock<gpu::SurfaceParams> surface_{"SurfaceParams"};
    gpu::PyramidLayout pyramid_{};
};

}  // namespace subscan
