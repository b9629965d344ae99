// GpuClear: its compute shader leaves exactly what the driver's clears leave, for every texture
// format and for buffers larger than one dispatch covers; and a whole frame renders the same
// picture by either path (on llvmpipe Auto takes the driver's, so without these tests the
// compute path, the one GPUs take, would run nowhere in CI).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/Camera.h"
#include "gpu/GpuClear.h"
#include "render/Renderer.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

// Not a multiple of the 8x8 work group: the edge groups must stop at the image's border.
constexpr int kWidth = 37;
constexpr int kHeight = 19;

std::vector<float> cleared(GpuClear& clears, TextureFormat format, const glm::vec4& value,
                           ClearPath path) {
    Texture texture(format, kWidth, kHeight, "test.cleared");
    texture.clear(glm::vec4(0.125f));  // what the clear must overwrite everywhere
    clears.texture(texture, value, path);
    return texture.readFloats();
}

TEST(GpuClearGLTest, EveryFloatFormatHoldsTheDriversValuesEverywhere) {
    GlContext& context = test::glTestContext();
    GpuClear clears(ShaderSources(), context.capabilities());
    const glm::vec4 value(0.25f, -0.5f, 0.75f, 1.0f);
    for (TextureFormat format :
         {TextureFormat::R8, TextureFormat::R32F, TextureFormat::RG32F, TextureFormat::RGBA16F,
          TextureFormat::RGBA32F, TextureFormat::RGBA8}) {
        const std::vector<float> byDriver = cleared(clears, format, value, ClearPath::Driver);
        const std::vector<float> byCompute = cleared(clears, format, value, ClearPath::Compute);
        ASSERT_EQ(byCompute.size(), byDriver.size());
        const int channels = static_cast<int>(byDriver.size()) / (kWidth * kHeight);
        const bool normalised = format == TextureFormat::R8 || format == TextureFormat::RGBA8;
        for (std::size_t i = 0; i < byDriver.size(); ++i) {
            // Both paths convert the same float to the same format: equal to the last bit.
            ASSERT_EQ(byCompute[i], byDriver[i])
                << "format " << static_cast<int>(format) << ", value " << i;
            // And that is the value asked for: exact in floats (all are multiples of 1/4);
            // unsigned normalised formats clamp to 0..1 and round to the nearest of 255 steps.
            const float asked = value[static_cast<int>(i) % channels];
            const float expected =
                normalised ? std::round(std::clamp(asked, 0.0f, 1.0f) * 255.0f) / 255.0f : asked;
            ASSERT_NEAR(byCompute[i], expected, 1e-6f) << "format " << static_cast<int>(format);
        }
    }
}

TEST(GpuClearGLTest, ARegionIsClearedAndNothingElse) {
    GlContext& context = test::glTestContext();
    GpuClear clears(ShaderSources(), context.capabilities());
    const glm::ivec2 origin(5, 3), size(17, 9);  // crossing work groups, off their grid
    for (ClearPath path : {ClearPath::Driver, ClearPath::Compute}) {
        Texture texture(TextureFormat::RGBA32F, kWidth, kHeight, "test.region");
        texture.clear(glm::vec4(0.125f));
        clears.textureRegion(texture, origin, size, glm::vec4(1.0f, 2.0f, 3.0f, 4.0f), path);
        const std::vector<float> values = texture.readFloats();
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const bool inside = x >= origin.x && y >= origin.y && x < origin.x + size.x &&
                                    y < origin.y + size.y;
                for (int c = 0; c < 4; ++c) {
                    ASSERT_EQ(values[4 * (y * kWidth + x) + c], inside ? c + 1.0f : 0.125f)
                        << (path == ClearPath::Compute ? "compute" : "driver") << " at " << x << ","
                        << y;
                }
            }
        }
    }
}

TEST(GpuClearGLTest, IntegerTexturesAndLargeBuffersHoldTheValueEverywhere) {
    GlContext& context = test::glTestContext();
    GpuClear clears(ShaderSources(), context.capabilities());
    Texture indices(TextureFormat::R32UI, kWidth, kHeight, "test.indices");
    indices.clearUint(7);
    clears.textureUint(indices, 0xFFFFFFFFu, ClearPath::Compute);
    for (std::uint32_t texel : indices.readUints()) {
        ASSERT_EQ(texel, 0xFFFFFFFFu);
    }
    // More words than the compute path's dispatch has invocations (4096 groups of 256): the
    // shader's loop must reach the end, and an odd count leaves no word out.
    const std::size_t words = 4096 * 256 * 2 + 37;
    Buffer buffer(words * sizeof(std::uint32_t), nullptr, "test.words");
    buffer.fill(7);
    clears.buffer(buffer, 0x7F800000u, ClearPath::Compute);
    const std::vector<std::uint32_t> values = buffer.read<std::uint32_t>();
    ASSERT_EQ(values.size(), words);
    for (std::size_t i = 0; i < words; ++i) {
        ASSERT_EQ(values[i], 0x7F800000u) << "word " << i;
    }
}

TEST(GpuClearGLTest, AutoClearsByComputeOnGpusOnly) {
    GlContext& context = test::glTestContext();
    const GpuClear clears(ShaderSources(), context.capabilities());
    EXPECT_EQ(clears.byCompute(ClearPath::Auto), !context.capabilities().software);
    EXPECT_TRUE(clears.byCompute(ClearPath::Compute));
    EXPECT_FALSE(clears.byCompute(ClearPath::Driver));
}

struct Image {
    std::string name;  // with the frame's index
    std::vector<float> values;
};

/// The pictures of a short orbit (the first frame restarts the temporal filter, the later
/// ones move it), then every image the last frame computes (it asks for all), cleared by
/// `path`, by a new renderer.
std::vector<Image> frames(const PointCloud& cloud, RenderSettings settings, ClearPath path) {
    settings.raster.clears = path;
    Renderer renderer(test::glTestContext(), cloud);
    std::vector<Image> images;
    for (int frame = 0; frame < 3; ++frame) {
        OrbitView orbit;
        orbit.yawDegrees = 20.0 + 4.0 * frame;
        orbit.distance = 3.0 * glm::length(cloud.bounds.max - cloud.bounds.min);
        const Camera camera = orbitCamera(cloud.bounds, orbit, 64, 48, 40.0);
        const bool last = frame == 2;
        renderer.render(camera, settings, last ? FrameOutputs::Everything : FrameOutputs::Picture);
        // Not the filled images: pull-push writes them only around the points, where they are
        // read, so off that region they hold whatever the memory held (on GPUs, not the same
        // from run to run).
        for (const char* name : {"image", "surfaceDepth", "mask", "normals", "radiance",
                                 "scatteredRadiance", "singleScattering", "sigmaA", "history"}) {
            if ((last || name == std::string("image")) && renderer.resources().has(name)) {
                images.push_back({std::string(name) + " of frame " + std::to_string(frame),
                                  renderer.resources().texture(name).readFloats()});
            }
        }
    }
    return images;
}

/// How many values differ, and the first that does.
std::string differences(const std::vector<float>& a, const std::vector<float>& b) {
    std::size_t count = 0, first = a.size();
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (a[i] != b[i] && !(std::isnan(a[i]) && std::isnan(b[i]))) {
            first = count++ == 0 ? i : first;
        }
    }
    if (count == 0) {
        return "none";
    }
    return std::to_string(count) + " of " + std::to_string(a.size()) + " values, the first at " +
           std::to_string(first) + ": " + std::to_string(a[first]) + " against " +
           std::to_string(b[first]);
}

TEST(GpuClearGLTest, EveryModeRendersTheSameImagesByEitherPath) {
    // Far enough that the cloud covers a part of the frame: the passes then clear what lies
    // outside the points' region, which is where the two paths could differ.
    const PointCloud cloud = makeSyntheticScene("sculpture?points=20000");
    RenderSettings surface;
    surface.raster.mode = RenderMode::Surface;
    surface.shading.lights = {DirectionalLight{}};  // and its light map's frame
    RenderSettings filtered = surface;
    filtered.temporal.enabled = true;
    RenderSettings scattered = surface;
    scattered.raster.mode = RenderMode::Sss;
    scattered.scattering.method = ScatteringMethod::Both;
    RenderSettings blended = surface;
    blended.raster.colorBlend = 0.01f;
    blended.raster.path = RasterPath::TwoPass32;
    for (const RenderSettings& settings : {surface, filtered, scattered, blended}) {
        const std::string run = toString(settings.raster.mode) +
                                (settings.temporal.enabled ? " filtered" : "") +
                                (settings.raster.colorBlend > 0.0f ? " blended" : "");
        const std::vector<Image> byDriver = frames(cloud, settings, ClearPath::Driver);
        const std::vector<Image> again = frames(cloud, settings, ClearPath::Driver);
        const std::vector<Image> byCompute = frames(cloud, settings, ClearPath::Compute);
        ASSERT_EQ(byCompute.size(), byDriver.size());
        for (std::size_t image = 0; image < byDriver.size(); ++image) {
            // A second run by the driver's path must repeat the first, or the comparison below
            // could not tell the paths apart (every pass is deterministic).
            ASSERT_EQ(again[image].values, byDriver[image].values)
                << run << ", " << byDriver[image].name << " differs between two runs: "
                << differences(again[image].values, byDriver[image].values);
            // Both paths clear to the same bits: equal exactly.
            EXPECT_EQ(byCompute[image].values, byDriver[image].values)
                << run << ", " << byDriver[image].name << ": "
                << differences(byCompute[image].values, byDriver[image].values);
        }
    }
}

}  // namespace
}  // namespace subscan
