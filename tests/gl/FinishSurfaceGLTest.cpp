// FinishSurfacePass: frames that keep only the picture finish the surface mode in one dispatch.
// It must show what the pass-by-pass chain shows: the same surface pixels at the same depths,
// and colours that differ only by the chain's rounding of its images to half floats.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>

#include "core/Camera.h"
#include "render/Renderer.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

bool ranPass(const FrameResult& result, const std::string& name) {
    return std::any_of(result.passes.begin(), result.passes.end(),
                       [&](const PassTiming& pass) { return pass.pass == name; });
}

struct Frame {
    std::vector<std::uint8_t> image;
    std::vector<float> surfaceDepth;
};

Frame render(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
             FrameOutputs outputs) {
    const FrameResult result = renderer.render(camera, settings, outputs);
    EXPECT_EQ(ranPass(result, "FinishSurface"), outputs == FrameOutputs::Picture);
    EXPECT_EQ(ranPass(result, "Shade"), outputs == FrameOutputs::Everything);
    return {renderer.readImage(), renderer.resources().texture("surfaceDepth").readFloats()};
}

/// A fused frame (first, so that nothing an earlier frame left in the images can stand in for
/// what it must write) against the per-pass one.
void expectSamePicture(const PointCloud& cloud, const Camera& camera,
                       const RenderSettings& settings) {
    Renderer renderer(test::glTestContext(), cloud);
    const Frame fused = render(renderer, camera, settings, FrameOutputs::Picture);
    const Frame perPass = render(renderer, camera, settings, FrameOutputs::Everything);
    // And the per-pass frame left nothing that changes the next fused one.
    EXPECT_EQ(render(renderer, camera, settings, FrameOutputs::Picture).image, fused.image);

    // Bit for bit: the same functions decide the mask and push the depth.
    ASSERT_EQ(fused.surfaceDepth.size(), perPass.surfaceDepth.size());
    std::size_t surfacePixels = 0;
    std::size_t depthDifferences = 0;
    for (std::size_t i = 0; i < perPass.surfaceDepth.size(); ++i) {
        surfacePixels += std::isinf(perPass.surfaceDepth[i]) ? 0 : 1;
        depthDifferences += fused.surfaceDepth[i] == perPass.surfaceDepth[i] ? 0 : 1;
    }
    EXPECT_EQ(depthDifferences, 0u);
    EXPECT_GT(surfacePixels, perPass.surfaceDepth.size() / 10) << "the view should show surface";

    ASSERT_EQ(fused.image.size(), perPass.image.size());
    std::size_t colourDifferences = 0;
    for (std::size_t i = 0; i < fused.image.size(); ++i) {
        const int difference = std::abs(int(fused.image[i]) - int(perPass.image[i]));
        // One 8-bit step: the chain stores the filled colour, the normal and the radiance as
        // half floats (11 significant bits), a relative change far below an sRGB step that
        // still moves values lying near a rounding boundary to the next step.
        ASSERT_LE(difference, 1) << "byte " << i;
        colourDifferences += difference == 0 ? 0 : 1;
    }
    // Most pixels agree exactly; a wrong normal, colour or light would move most of them.
    EXPECT_LT(colourDifferences, fused.image.size() / 20);
}

TEST(FinishSurfaceGLTest, FramedObjectLooksAsPassByPass) {
    // Background all around: the frame is restricted to the points' bounds, and the picture
    // outside them is the cleared background.
    const PointCloud cloud = makeSyntheticScene("sculpture?points=20000");
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.shading.lights.push_back({{0.3f, 1.0f, 0.5f}, {0.6f, 0.5f, 0.4f}});
    // With the normals' outline rule FinishSurface reads the mask FillRemoval drew; without it,
    // it draws the mask itself.
    for (const bool outlineNormals : {true, false}) {
        SCOPED_TRACE(outlineNormals ? "normals follow the outline" : "normals as blended");
        settings.surface.outlineNormals = outlineNormals;
        expectSamePicture(cloud, orbitCamera(cloud.bounds, {30.0, 20.0}, 161, 97, 45.0), settings);
    }
}

TEST(FinishSurfaceGLTest, CloseUpLooksAsPassByPass) {
    // The surface leaves the image on every side and its points lie pixels apart: push,
    // fill removal and normals reach the border and the coarse levels everywhere.
    const PointCloud cloud = makeSyntheticScene("sculpture?points=20000");
    OrbitView close;
    close.yawDegrees = 200.0;
    close.distance = 0.3 * glm::length(cloud.bounds.extent());
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    expectSamePicture(cloud, orbitCamera(cloud.bounds, close, 120, 90, 45.0), settings);
}

/// The pictures of the two renderers: equal up to the per-pass chain's half floats. Most bytes
/// agree exactly; a wrong blend, depth or history would move most of them. Bytes more than one
/// step apart may number `beyondOneStep`, none more than `steps` apart.
void expectSameBlend(Renderer& fused, Renderer& perPass, int steps, std::size_t beyondOneStep) {
    const std::vector<std::uint8_t> a = fused.readImage(), b = perPass.readImage();
    ASSERT_EQ(a.size(), b.size());
    std::size_t differences = 0, large = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const int difference = std::abs(int(a[i]) - int(b[i]));
        ASSERT_LE(difference, steps) << "byte " << i;
        differences += difference == 0 ? 0 : 1;
        large += difference > 1 ? 1 : 0;
    }
    EXPECT_LT(differences, a.size() / 20);
    EXPECT_LE(large, beyondOneStep);
}

TEST(FinishSurfaceGLTest, TemporalFilterBlendsAsItsOwnPassDoes) {
    // A still camera's 8 jittered frames: FinishSurface blends them itself (pictures only),
    // pass by pass TemporalPass does. Moving, FinishSurface leaves the blend to TemporalPass,
    // which then finds the depth in the radiance's alpha instead of in "surfaceDepth".
    const PointCloud cloud = makeSyntheticScene("sculpture?points=20000");
    const Camera camera = orbitCamera(cloud.bounds, {30.0, 20.0}, 161, 97, 45.0);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.temporal.enabled = true;
    Renderer fused(test::glTestContext(), cloud);
    Renderer perPass(test::glTestContext(), cloud);
    for (int frame = 0; frame < 8; ++frame) {
        const FrameResult result = fused.render(camera, settings);
        EXPECT_TRUE(ranPass(result, "FinishSurface"));
        EXPECT_FALSE(ranPass(result, "Temporal")) << "frame " << frame;
        EXPECT_TRUE(
            ranPass(perPass.render(camera, settings, FrameOutputs::Everything), "Temporal"));
    }
    // As above: the chain's half floats move a value near a rounding boundary by a step.
    expectSameBlend(fused, perPass, 1, 0);
    Camera moved = camera;
    for (int frame = 1; frame <= 3; ++frame) {
        SCOPED_TRACE(frame);
        moved.view = glm::rotate(moved.view, glm::radians(1.0), glm::dvec3(0.0, 1.0, 0.0));
        const FrameResult moving = fused.render(moved, settings);
        EXPECT_TRUE(ranPass(moving, "FinishSurface"));
        EXPECT_TRUE(ranPass(moving, "Temporal"));
        perPass.render(moved, settings, FrameOutputs::Everything);
        // Moving, the history is clipped to the neighbourhood's mean ± one standard deviation.
        // Where the neighbourhood is nearly flat the deviation is of the order of the chain's
        // rounding, so the clip can turn that rounding into a few steps: measured up to 4 in
        // at most 5 of 62,468 bytes over these three frames.
        expectSameBlend(fused, perPass, 6, 20);
    }
}

TEST(FinishSurfaceGLTest, OnlyTheSurfaceModesFinalFullResolutionPictureIsFused) {
    const PointCloud cloud = makeSyntheticScene("sphere?points=3000");
    Renderer renderer(test::glTestContext(), cloud);
    const Camera camera = orbitCamera(cloud.bounds, {}, 64, 48, 45.0);
    RenderSettings surface;
    surface.raster.mode = RenderMode::Surface;
    RenderSettings stage = surface;
    stage.raster.stage = Stage::Normals;
    RenderSettings half = surface;
    half.raster.resolution = Resolution::Half;
    RenderSettings scattering;
    scattering.raster.mode = RenderMode::Sss;
    for (const RenderSettings& settings : {stage, half, scattering}) {
        EXPECT_FALSE(ranPass(renderer.render(camera, settings), "FinishSurface"))
            << toString(settings.raster.mode) << " " << toString(settings.raster.stage);
    }
    EXPECT_TRUE(ranPass(renderer.render(camera, surface), "FinishSurface"));
    // A one-pixel image has no pyramid level above its pixel.
    Camera pixel = camera;
    pixel.width = 1;
    pixel.height = 1;
    EXPECT_FALSE(ranPass(renderer.render(pixel, surface), "FinishSurface"));
}

}  // namespace
}  // namespace subscan
