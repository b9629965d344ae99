#pragma once

#include "core/Camera.h"
#include "gpu/GlObjects.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

/// The frame-wide uniform blocks every pass may read: the camera (FrameParams), the pyramid
/// layout for the image size and the reconstruction radii (SurfaceParams, radii = settings x h).
/// update() fills and binds them; the Renderer calls it once per frame, tests before running a
/// single pass.
class FrameUniforms {
  public:
    const gpu::PyramidLayout& update(const Camera& camera, const RenderSettings& settings,
                                     double spacing, const glm::dvec3& cloudOrigin);
    const gpu::PyramidLayout& pyramid() const { return pyramid_; }

  private:
    UniformBlock<gpu::FrameParams> frame_{"FrameParams"};
    UniformBlock<gpu::PyramidLayout> pyramidBlock_{"PyramidLayout"};
    UniformBlock<gpu::SurfaceParams> surface_{"SurfaceParams"};
    gpu::PyramidLayout pyramid_{};
};

}  // namespace subscan
