// Reconstruction at half resolution (RasterSettings::resolution): the pipeline's images are
// those of the reduced camera rendered at full resolution, and Present scales them up exactly
// as its CPU twin below does, also where the frame is restricted to the points' bounds.
#include <cmath>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>
#include <glm/common.hpp>

#include "core/Srgb.h"
#include "render/ReducedResolution.h"
#include "render/Renderer.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

/// Present's scaling on the CPU: bilinear over the reduced radiance shown over the background
/// by its alpha (the share of the texel the surface covers, OutlineCoveragePass's), then
/// 8-bit sRGB.
std::vector<std::uint8_t> scaledUp(const Camera& output, const Camera& reduced,
                                   const std::vector<float>& radiance,
                                   const glm::vec3& background) {
    auto colorAt = [&](glm::ivec2 texel) {
        texel = glm::clamp(texel, glm::ivec2(0), glm::ivec2(reduced.width, reduced.height) - 1);
        const std::size_t i = static_cast<std::size_t>(texel.y * reduced.width + texel.x);
        return glm::mix(background,
                        glm::vec3(radiance[4 * i], radiance[4 * i + 1], radiance[4 * i + 2]),
                        radiance[4 * i + 3]);
    };
    std::vector<std::uint8_t> image;
    for (int y = 0; y < output.height; ++y) {
        for (int x = 0; x < output.width; ++x) {
            const glm::dvec2 position =
                reducedPosition(output, reduced, 2, glm::dvec2(x + 0.5, y + 0.5)) - 0.5;
            const glm::ivec2 first(glm::floor(position));
            const glm::vec2 t(position - glm::dvec2(first));
            const glm::vec3 color =
                glm::mix(glm::mix(colorAt(first), colorAt(first + glm::ivec2(1, 0)), t.x),
                         glm::mix(colorAt(first + glm::ivec2(0, 1)), colorAt(first + 1), t.x), t.y);
            for (int c = 0; c < 3; ++c) {
                image.push_back(srgb8Channel(color[c]));
            }
            image.push_back(255);
        }
    }
    return image;
}

TEST(ReducedResolutionGLTest, HalfResolutionIsTheReducedFrameScaledUp) {
    const PointCloud cloud = makeSyntheticScene("sculpture?points=20000");
    Renderer renderer(test::glTestContext(), cloud);
    // Odd sizes, and the object framed with background around it: the frame is restricted to
    // the points' bounds, so Present's region must cover every pixel the surface reaches.
    const Camera camera = orbitCamera(cloud.bounds, {30.0, 20.0}, 161, 97, 45.0);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.raster.resolution = Resolution::Half;
    ASSERT_EQ(renderer.render(camera, settings).divisor, 2);
    const Camera reduced = renderer.pipelineCamera();
    ASSERT_EQ(reduced.width, 81);
    ASSERT_EQ(reduced.height, 49);
    const std::vector<float> radiance = renderer.resources().texture("radiance").readFloats();
    const std::vector<float> depth = renderer.resources().texture("surfaceDepth").readFloats();
    const std::vector<std::uint8_t> image = renderer.readImage();

    const glm::vec3& background = settings.raster.backgroundSrgb;
    const std::vector<std::uint8_t> expected = scaledUp(
        camera, reduced, radiance,
        {srgbToLinear(background.r), srgbToLinear(background.g), srgbToLinear(background.b)});
    ASSERT_EQ(image.size(), expected.size());
    int surfacePixels = 0;
    for (std::size_t i = 0; i < image.size(); ++i) {
        // One 8-bit step: the GPU's float mix and pow round differently at half-way values.
        ASSERT_LE(std::abs(int(image[i]) - int(expected[i])), 1) << "byte " << i;
    }
    for (const float value : depth) {
        surfacePixels += std::isinf(value) ? 0 : 1;
    }
    EXPECT_GT(surfacePixels, 81 * 49 / 10) << "the surface should fill part of the frame";
    EXPECT_LT(surfacePixels, 81 * 49 * 9 / 10) << "the frame should show background too";
    int partlyCovered = 0;
    for (std::size_t i = 3; i < radiance.size(); i += 4) {
        partlyCovered += radiance[i] > 0.0f && radiance[i] < 1.0f ? 1 : 0;
    }
    EXPECT_GT(partlyCovered, 0) << "the outline should be anti-aliased";

    // The same reduced camera at full resolution: the very same pipeline images.
    settings.raster.resolution = Resolution::Full;
    ASSERT_EQ(renderer.render(reduced, settings, FrameOutputs::Everything).divisor, 1);
    EXPECT_EQ(renderer.resources().texture("radiance").readFloats(), radiance);
    EXPECT_EQ(renderer.resources().texture("surfaceDepth").readFloats(), depth);
}

TEST(ReducedResolutionGLTest, PointModesIgnoreTheResolution) {
    const PointCloud cloud = makeSyntheticScene("sphere?points=3000");
    Renderer renderer(test::glTestContext(), cloud);
    const Camera camera = orbitCamera(cloud.bounds, {}, 64, 48, 45.0);
    RenderSettings settings;
    settings.raster.resolution = Resolution::Half;
    for (const RenderMode mode : {RenderMode::Points, RenderMode::PointsGl}) {
        settings.raster.mode = mode;
        EXPECT_EQ(renderer.render(camera, settings).divisor, 1) << toString(mode);
        EXPECT_EQ(renderer.pipelineCamera().width, 64);
    }
}

}  // namespace
}  // namespace subscan
