#include "support/PassHarness.h"

#include <string>
#include <vector>

#include <glm/packing.hpp>

#include "support/GlTestSupport.h"

namespace subscan::test {

namespace {

/// Passes after the rasterizer never read the cloud, but the frame context holds one.
PointCloud onePointCloud() {
    PointCloudBuilder builder({}, 1);
    builder.add({});
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

}  // namespace

PassHarness::PassHarness(int width, int height, const RenderSettings& settings, double spacing,
                         double fovyDegrees, bool localSpacing)
    : settings_(settings),
      spacing_(spacing),
      cloud_(onePointCloud(), glTestContext().capabilities()) {
    camera_.width = width;
    camera_.height = height;
    camera_.fovyDegrees = fovyDegrees;
    camera_.nearPlane = 0.1;
    camera_.farPlane = 100.0;
    if (localSpacing) {
        cloud_.setLocalSpacing({glm::vec4(0.0f, 0.0f, 0.0f, 1.0f)});
    }
    layout_ = uniforms_.update(camera_, settings_, spacing_, cloud_);
    if (settings_.surface.localSpacing) {
        uploadAcrossAxes(std::vector<glm::vec2>(static_cast<std::size_t>(width) * height));
    }
}

void PassHarness::setSparseSpacingRatio(float ratio) {
    cloud_.setLocalSpacing({glm::vec4(0.0f, 0.0f, 0.0f, ratio)});
    layout_ = uniforms_.update(camera_, settings_, spacing_, cloud_);
}

void PassHarness::uploadAcrossAxes(const std::vector<glm::vec2>& axes) {
    std::vector<std::uint32_t> packed(axes.size());
    for (std::size_t i = 0; i < axes.size(); ++i) {
        packed[i] = glm::packHalf2x16(axes[i]);
    }
    resources_.ensureBuffer("acrossLines", packed.size() * sizeof(std::uint32_t))
        .upload(0, packed.size() * sizeof(std::uint32_t), packed.data());
}

std::vector<glm::vec2> PassHarness::acrossAxes() const {
    const std::vector<std::uint32_t> packed =
        resources_.buffer("acrossLines").read<std::uint32_t>();
    std::vector<glm::vec2> axes(packed.size());
    for (std::size_t i = 0; i < packed.size(); ++i) {
        axes[i] = glm::unpackHalf2x16(packed[i]);
    }
    return axes;
}

FrameContext PassHarness::context() {
    return {camera_,    cloud_,  settings_, glTestContext().capabilities(),
            resources_, clears_, layout_,   spacing_};
}

void PassHarness::setCamera(const Camera& camera) {
    camera_ = camera;
    layout_ = uniforms_.update(camera_, settings_, spacing_, cloud_);
}

glm::dvec3 PassHarness::viewPosition(double wx, double wy, double depth) const {
    const double f = focal();
    return {(wx - 0.5 * camera_.width) * depth / f, (0.5 * camera_.height - wy) * depth / f,
            -depth};
}

}  // namespace subscan::test
