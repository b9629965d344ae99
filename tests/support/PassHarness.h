#pragma once

#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/Camera.h"
#include "gpu/ShaderSources.h"
#include "render/FrameResources.h"
#include "render/FrameUniforms.h"
#include "render/GpuPointCloud.h"
#include "render/RenderPass.h"
#include "render/RenderSettings.h"
#include "support/GlTestSupport.h"

namespace subscan::test {

/// A frame of the pipeline outside the Renderer, for testing one pass on inputs the test
/// uploads itself: a camera looking down −z, the frame uniforms, named resources and the
/// context a pass runs with. With `localSpacing` the cloud carries a local spacing, so the passes
/// scale their radii by the "color" image's alpha and the pulled ratios.
class PassHarness {
  public:
    PassHarness(int width, int height, const RenderSettings& settings, double spacing,
                double fovyDegrees = 50.0, bool localSpacing = false);

    FrameContext context();
    /// With the local spacing: the spacing ratio the cloud declares (its sparse one, 1 until
    /// set), which sets how far beyond the points the passes' region reaches; a test that
    /// uploads ratios above 1 declares its largest.
    void setSparseSpacingRatio(float ratio);
    /// Per pixel, the across-lines axis the rasterizer would leave (its "acrossLines": a
    /// doubled-angle vector of length 1 - w / |across|, 0 where no scan lines lie apart), with
    /// the local spacing setting; until set, 0 everywhere.
    void uploadAcrossAxes(const std::vector<glm::vec2>& axes);
    /// The axes as the passes read them (half floats).
    std::vector<glm::vec2> acrossAxes() const;
    /// Another camera (its size must stay) for the passes run after this; uniforms updated.
    void setCamera(const Camera& camera);
    FrameResources& resources() { return resources_; }
    const Camera& camera() const { return camera_; }
    const RenderSettings& settings() const { return settings_; }
    const ShaderSources& sources() const { return sources_; }
    double focal() const { return camera_.focalLengthPixels(); }
    double spacing() const { return spacing_; }
    /// The view-space point seen at window position (wx, wy) (pixel centres at index + 0.5,
    /// row 0 at the top) at linear depth `depth`: the CPU twin of viewPositionAt in GLSL.
    glm::dvec3 viewPosition(double wx, double wy, double depth) const;

  private:
    Camera camera_;
    RenderSettings settings_;
    double spacing_;
    GpuPointCloud cloud_;
    FrameUniforms uniforms_;
    gpu::PyramidLayout layout_{};
    FrameResources resources_;
    ShaderSources sources_;
    GpuClear clears_{sources_, glTestContext().capabilities()};
};

}  // namespace subscan::test
