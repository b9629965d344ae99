// Renderer::replaceCloud: a renderer that drew one cloud and was given another draws what a
// renderer made for the second one draws, shadows included (its light maps are built again) and
// through the temporal filter (which starts afresh).
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Camera.h"
#include "core/LocalSpacing.h"
#include "render/Renderer.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 120;

RenderSettings shadowedSurface() {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    DirectionalLight light;
    light.direction = {0.6f, 0.8f, 0.2f};
    settings.shading.lights = {light};
    settings.shading.shadows = true;
    // Through the temporal filter: a history of the old cloud must not blend into the new.
    settings.temporal.enabled = true;
    return settings;
}

/// Channels that differ by more than one step between two RGBA8 pictures.
int differingChannels(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    int count = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        count += std::abs(a[i] - b[i]) > 1 ? 1 : 0;
    }
    return count;
}

TEST(RendererGLTest, AReplacedCloudRendersAsARendererMadeForIt) {
    GlContext& context = test::glTestContext();
    const PointCloud torus = makeSyntheticScene("torus");
    const PointCloud sculpture = makeSyntheticScene("sculpture");
    const RenderSettings settings = shadowedSurface();
    const Camera torusView = orbitCamera(torus.bounds, OrbitView{}, kWidth, kHeight, 45.0);
    const Camera sculptureView = orbitCamera(sculpture.bounds, OrbitView{}, kWidth, kHeight, 45.0);

    Renderer made(context, sculpture, estimatePointSpacing(sculpture));
    made.render(sculptureView, settings);
    const std::vector<std::uint8_t> expected = made.readImage();

    Renderer replaced(context, torus, estimatePointSpacing(torus));
    replaced.render(torusView, settings);
    const std::vector<std::uint8_t> torusPicture = replaced.readImage();
    replaced.replaceCloud(sculpture, estimatePointSpacing(sculpture));
    EXPECT_EQ(replaced.gpuCloud().size(), sculpture.size());
    EXPECT_DOUBLE_EQ(replaced.spacing(), made.spacing());
    replaced.render(sculptureView, settings);
    const std::vector<std::uint8_t> picture = replaced.readImage();
    ASSERT_EQ(picture.size(), expected.size());
    // One step: the same passes over the same points; only a tie between points resolved
    // in another order could differ, and by little.
    EXPECT_EQ(differingChannels(picture, expected), 0);
    // The scenes differ enough that a renderer still drawing the torus would fail above.
    EXPECT_GT(differingChannels(torusPicture, expected), static_cast<int>(expected.size()) / 20);
}

TEST(RendererGLTest, ACloudUploadedInStepsRendersAsARendererMadeForIt) {
    GlContext& context = test::glTestContext();
    const PointCloud torus = makeSyntheticScene("torus");
    const PointCloud sculpture = makeSyntheticScene("sculpture");
    const RenderSettings settings = shadowedSurface();
    const Camera view = orbitCamera(sculpture.bounds, OrbitView{}, kWidth, kHeight, 45.0);
    const PointSpacing spacing = estimatePointSpacing(sculpture);

    Renderer made(context, sculpture, spacing);
    made.render(view, settings);
    const std::vector<std::uint8_t> expected = made.readImage();

    Renderer replaced(context, torus, estimatePointSpacing(torus));
    replaced.render(view, settings);
    const std::vector<std::uint8_t> torusPicture = replaced.readImage();
    GpuPointCloudUpload upload =
        replaced.startUpload(sculpture, PointMemory::Copy, packPointAttributes(spacing.local, {}));
    // A quarter at a time, with frames of the torus in between.
    const std::size_t quarter = upload.bytesLeft() / 4 + 1;
    for (int step = 0; step < 3; ++step) {
        EXPECT_FALSE(upload.advance(quarter));
        replaced.render(view, settings);
    }
    EXPECT_TRUE(upload.advance(quarter));
    // An upload of other points is refused, and the renderer keeps its own.
    PointCloud half;
    half.positions.assign(torus.positions.begin(),
                          torus.positions.begin() + static_cast<std::ptrdiff_t>(torus.size() / 2));
    half.bounds = torus.bounds;
    EXPECT_THAT(test::errorMessage([&] {
                    replaced.replaceCloud(torus, estimatePointSpacing(torus),
                                          replaced.startUpload(half, PointMemory::Copy, {}));
                }),
                ::testing::HasSubstr("points given for a cloud of"));
    EXPECT_EQ(replaced.gpuCloud().size(), torus.size());
    replaced.replaceCloud(sculpture, spacing, std::move(upload));
    EXPECT_EQ(replaced.gpuCloud().size(), sculpture.size());
    EXPECT_EQ(replaced.gpuCloud().hasLocalSpacing(), made.gpuCloud().hasLocalSpacing());
    replaced.render(view, settings);
    // As above: the same passes over the same points.
    EXPECT_EQ(differingChannels(replaced.readImage(), expected), 0);
    EXPECT_GT(differingChannels(torusPicture, expected), static_cast<int>(expected.size()) / 20);
}

}  // namespace
}  // namespace subscan
