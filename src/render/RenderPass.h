#pragma once

#include <string_view>
#include <vector>

#include "core/Camera.h"
#include "gpu/GlContext.h"
#include "render/FrameResources.h"
#include "render/GpuPointCloud.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

/// Everything a pass may use while it runs. The frame-wide uniform blocks (FrameParams,
/// PyramidLayout, SurfaceParams) are already bound.
struct FrameContext {
    const Camera& camera;
    const GpuPointCloud& cloud;
    const RenderSettings& settings;
    const GlCapabilities& capabilities;
    FrameResources& resources;
    const gpu::PyramidLayout& pyramid;
    double spacing;  // the point spacing h, scene units

    int width() const { return camera.width; }
    int height() const { return camera.height; }
};

/// One step of the frame pipeline: one class and one shader of the same name (Falcor's
/// RenderPass). It declares the images it reads and writes by name so the runner can check the
/// wiring, time it and dump any of its outputs.
class RenderPass {
  public:
    virtual ~RenderPass() = default;
    virtual std::string_view name() const = 0;
    virtual std::vector<std::string_view> inputs() const = 0;
    virtual std::vector<std::string_view> outputs() const = 0;
    virtual void execute(FrameContext& frame) = 0;
};

}  // namespace subscan
