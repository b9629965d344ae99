// The compute rasterizer (both paths), the GL_POINTS baseline and Present against a CPU
// reference of the same rule: per pixel the nearest point, ties to the smaller index.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/matrix.hpp>
#include <glm/packing.hpp>

#include "core/Camera.h"
#include "core/Error.h"
#include "core/Srgb.h"
#include "render/RasterizePointsPass.h"
#include "render/Renderer.h"
#include "support/GlTestSupport.h"

namespace subscan {

/// googletest names a RasterPath parameter by this (instead of its bytes) in listings.
void PrintTo(RasterPath path, std::ostream* out) {
    *out << toString(path);
}

namespace {

constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;

Camera smallCamera() {
    Camera camera;
    camera.width = 37;  // odd sizes catch row/column mix-ups
    camera.height = 23;
    camera.fovyDegrees = 50.0;
    camera.nearPlane = 0.5;
    camera.farPlane = 20.0;
    camera.view = glm::lookAt(glm::dvec3(0.3, -0.2, 5.0), glm::dvec3(0.0), glm::dvec3(0, 1, 0));
    return camera;
}

/// A point in file coordinates that projects inside pixel (x, y) (row 0 at the top), away from
/// its edges by at least 0.2 px, at linear depth `depth`.
glm::dvec3 pointAtPixel(const Camera& camera, double x, double y, double depth) {
    const double tanHalf = std::tan(0.5 * glm::radians(camera.fovyDegrees));
    const double aspect = static_cast<double>(camera.width) / camera.height;
    const double ndcX = 2.0 * x / camera.width - 1.0;
    const double ndcY = 1.0 - 2.0 * y / camera.height;
    const glm::dvec4 view(ndcX * depth * tanHalf * aspect, ndcY * depth * tanHalf, -depth, 1.0);
    return glm::dvec3(glm::inverse(camera.view) * view);
}

struct Reference {
    std::vector<std::uint32_t> winner;  // per pixel
    std::vector<double> depth;
};

/// Calls visit(point, view-space position, pixel) for every point of `cloud` within the
/// camera's near and far planes and image: the stored (float, cloud-relative) positions
/// projected in double with the pixel convention of docs/cli.md, in the points' order.
template <typename Visit>
void forEachPointOnScreen(const PointCloud& cloud, const Camera& camera, Visit visit) {
    const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloud.origin);
    const glm::dmat4 projection = camera.projection();
    for (std::uint32_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec4 view = viewFromCloud * glm::dvec4(glm::dvec3(cloud.positions[i]), 1.0);
        if (-view.z < camera.nearPlane || -view.z > camera.farPlane) {
            continue;
        }
        const glm::dvec4 clip = projection * view;
        const double x = std::floor((clip.x / clip.w + 1.0) * 0.5 * camera.width);
        const double y = std::floor((1.0 - clip.y / clip.w) * 0.5 * camera.height);
        if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) {
            continue;
        }
        visit(i, glm::dvec3(view),
              static_cast<std::size_t>(y) * camera.width + static_cast<std::size_t>(x));
    }
}

/// The CPU reference of the nearest point per pixel.
Reference rasterizeOnCpu(const PointCloud& cloud, const Camera& camera) {
    const std::size_t pixels = static_cast<std::size_t>(camera.width * camera.height);
    Reference reference{std::vector<std::uint32_t>(pixels, kEmpty),
                        std::vector<double>(pixels, std::numeric_limits<double>::infinity())};
    forEachPointOnScreen(cloud, camera, [&](std::uint32_t i, glm::dvec3 view, std::size_t pixel) {
        if (-view.z < reference.depth[pixel]) {  // equal depth keeps the earlier (smaller) index
            reference.depth[pixel] = -view.z;
            reference.winner[pixel] = i;
        }
    });
    return reference;
}

/// ~4 points per covered pixel at well-separated depths, exact duplicates (depth ties), and
/// points outside the image and outside near/far.
PointCloud testCloud(const Camera& camera, std::uint32_t seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> jitter(0.2, 0.8);
    // Every point its own depth on a 1.5 mm grid: distinct depths differ far beyond float
    // rounding (~1e-6), so only the deliberate duplicates below tie.
    std::vector<int> depthSteps(3000);
    std::iota(depthSteps.begin(), depthSteps.end(), 0);
    std::shuffle(depthSteps.begin(), depthSteps.end(), random);
    PointCloudBuilder builder({.color = true}, 4000);
    auto add = [&](const glm::dvec3& position) {
        PointRecord record;
        record.position = position;
        const auto value = static_cast<std::uint32_t>(random());
        record.color = {static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8),
                        static_cast<std::uint8_t>(value >> 16), 255};
        builder.add(record);
    };
    for (int i = 0; i < 3000; ++i) {
        const int x = static_cast<int>(random() % camera.width);
        const int y = static_cast<int>(random() % camera.height);
        const double depth = 1.0 + 0.0015 * depthSteps[static_cast<std::size_t>(i)];
        const glm::dvec3 p = pointAtPixel(camera, x + jitter(random), y + jitter(random), depth);
        add(p);
        if (i % 7 == 0) {
            add(p);  // an exact duplicate: same depth bits, the smaller index must win
        }
    }
    add(pointAtPixel(camera, -3.5, 4.5, 3.0));                  // left of the image
    add(pointAtPixel(camera, 10.5, camera.height + 2.5, 3.0));  // below it
    add(pointAtPixel(camera, 5.5, 5.5, 0.3));                   // nearer than near
    add(pointAtPixel(camera, 6.5, 6.5, 25.0));                  // beyond far
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

/// Gives every point a random direction, half of them facing away from the eye (a normal's sign
/// is arbitrary without a sensor), but every ninth point none.
void giveRandomNormals(PointCloud& cloud, std::uint32_t seed) {
    std::mt19937 random(seed);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        cloud.normals[i] =
            i % 9 == 0 ? glm::vec3(0.0f)
                       : glm::normalize(glm::vec3(gauss(random), gauss(random), gauss(random)));
    }
}

/// Checks the last frame against `reference` (empty pixels: +inf and no colour) and returns
/// how many pixels hold a point.
std::size_t expectMatchesReference(Renderer& renderer, const PointCloud& cloud,
                                   const Reference& reference) {
    const std::vector<std::uint32_t> winners =
        renderer.rasterizePass()->readWinners(renderer.resources());
    const std::vector<float> depth = renderer.resources().texture("depth").readFloats();
    const std::vector<float> color = renderer.resources().texture("color").readFloats();
    std::size_t covered = 0;
    for (std::size_t pixel = 0; pixel < reference.winner.size(); ++pixel) {
        if (winners[pixel] != reference.winner[pixel]) {
            ADD_FAILURE() << "pixel " << pixel << ": point " << winners[pixel] << " instead of "
                          << reference.winner[pixel];
            return 0;
        }
        if (reference.winner[pixel] == kEmpty) {
            EXPECT_TRUE(std::isinf(depth[pixel])) << "pixel " << pixel;
            for (int c = 0; c < 4; ++c) {
                EXPECT_EQ(color[4 * pixel + c], 0.0f) << "pixel " << pixel;
            }
            continue;
        }
        ++covered;
        // The GPU transforms in float: a few ulp of a depth around 5 is ~1e-6.
        EXPECT_NEAR(depth[pixel], reference.depth[pixel], 1e-5 * reference.depth[pixel]);
        const Rgba8 expected = cloud.colors[reference.winner[pixel]];
        const std::uint8_t channels[3] = {expected.r, expected.g, expected.b};
        for (int c = 0; c < 3; ++c) {
            // RGBA16F keeps 11 significant bits: 1e-3 relative, plus the sRGB curve's rounding.
            EXPECT_NEAR(color[4 * pixel + c], srgbToLinear(channels[c] / 255.0f), 2e-3);
        }
    }
    return covered;
}

/// Per pixel, what a blend sums: its points' values (colours, or normals) and their count.
struct BlendSums {
    std::vector<glm::dvec3> sums;
    std::vector<int> counts;

    int pixelsOfSeveral() const {
        return static_cast<int>(
            std::count_if(counts.begin(), counts.end(), [](int count) { return count > 1; }));
    }
};

/// The colour blend's sums: the linear colours of the points within `blend` relative depth of
/// their pixel's nearest.
BlendSums blendColorsOnCpu(const PointCloud& cloud, const Camera& camera,
                           const Reference& reference, float blend) {
    const std::size_t pixels = reference.winner.size();
    BlendSums blended{std::vector<glm::dvec3>(pixels, glm::dvec3(0.0)),
                      std::vector<int>(pixels, 0)};
    forEachPointOnScreen(cloud, camera, [&](std::uint32_t i, glm::dvec3 view, std::size_t pixel) {
        if (-view.z <= reference.depth[pixel] * (1.0 + blend)) {
            blended.sums[pixel] += glm::dvec3(linearColor(cloud.colors[i]));
            ++blended.counts[pixel];
        }
    });
    return blended;
}

/// Checks the last frame's depth and colours against the colour blend's sums.
void expectBlendedColors(Renderer& renderer, const Reference& reference, const BlendSums& blended) {
    const std::vector<float> depth = renderer.resources().texture("depth").readFloats();
    const std::vector<float> color = renderer.resources().texture("color").readFloats();
    for (std::size_t pixel = 0; pixel < reference.winner.size(); ++pixel) {
        const int count = blended.counts[pixel];
        if (count == 0) {
            EXPECT_TRUE(std::isinf(depth[pixel])) << "pixel " << pixel;
            continue;
        }
        EXPECT_NEAR(depth[pixel], reference.depth[pixel], 1e-5 * reference.depth[pixel]);
        for (int c = 0; c < 3; ++c) {
            // Fixed point of 1/16384 per point, then RGBA16F's 11 significant bits: dark
            // colours keep their 8-bit steps (the darkest, 3e-4, is 5 units).
            const double expected = blended.sums[pixel][c] / count;
            EXPECT_NEAR(color[4 * pixel + c], expected, 1.0 / 16384 + expected / 1024)
                << "pixel " << pixel << " of " << count << " points";
        }
    }
}

/// The compute path under test, run whole and in chunks of 97 points.
class RasterPathGLTest : public ::testing::TestWithParam<RasterPath> {};

TEST_P(RasterPathGLTest, MatchesTheCpuReferenceWithChunking) {
    GlContext& context = test::glTestContext();
    if (GetParam() == RasterPath::Int64 && !context.capabilities().int64Atomics) {
        GTEST_SKIP() << context.capabilities().renderer
                     << " has no 64-bit atomics (GL_NV_shader_atomic_int64); the int64 path "
                        "is tested where a driver has them";
    }
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 1);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    // Borrowed points start each chunk of 97 at an offset no alignment rule favours: llvmpipe
    // reads them in place, other drivers may refuse (and the points are copied).
    const bool llvmpipe = context.capabilities().renderer.find("llvmpipe") != std::string::npos;
    for (const std::size_t chunk : {std::size_t{0}, std::size_t{97}}) {
        for (const PointMemory memory : {PointMemory::Copy, PointMemory::Borrow}) {
            SCOPED_TRACE(chunk ? "chunks of 97" : "one chunk");
            SCOPED_TRACE(memory == PointMemory::Copy ? "copied points" : "borrowed points");
            Renderer renderer(context, cloud, std::nullopt, chunk, memory);
            if (memory == PointMemory::Copy || llvmpipe) {
                EXPECT_EQ(renderer.gpuCloud().borrowsPositions(), memory == PointMemory::Borrow);
            }
            RenderSettings settings;
            settings.raster.path = GetParam();
            renderer.render(camera, settings);
            // The test cloud covers most pixels.
            EXPECT_GT(expectMatchesReference(renderer, cloud, reference),
                      reference.winner.size() / 2);
        }
    }
}

TEST_P(RasterPathGLTest, ColorAlphaIsTheWinnersLocalSpacingOnScreen) {
    GlContext& context = test::glTestContext();
    if (GetParam() == RasterPath::Int64 && !context.capabilities().int64Atomics) {
        GTEST_SKIP() << context.capabilities().renderer << " has no 64-bit atomics";
    }
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 2);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    // Random spacings, half of the points with an across vector of up to 12 h in any
    // direction (towards the eye too); rounded to halves as the GPU stores them.
    std::mt19937 random(4);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<glm::vec4> spacing(cloud.size());
    for (std::size_t i = 0; i < spacing.size(); ++i) {
        const glm::vec3 across = i % 2 == 0
                                     ? glm::vec3(0.0f)
                                     : 7.0f * glm::vec3(unit(random), unit(random), unit(random));
        spacing[i] = glm::unpackHalf(glm::packHalf(glm::vec4(across, 2.0f + unit(random))));
    }
    for (const std::size_t chunk : {std::size_t{0}, std::size_t{97}}) {
        SCOPED_TRACE(chunk ? "chunks of 97" : "one chunk");
        Renderer renderer(context, cloud, 0.01, chunk);
        renderer.setLocalSpacing(spacing);
        RenderSettings settings;
        settings.raster.path = GetParam();
        for (const bool local : {true, false}) {
            settings.surface.localSpacing = local;
            renderer.render(camera, settings);
            const std::vector<float> color = renderer.resources().texture("color").readFloats();
            std::vector<std::uint32_t> axes;
            if (local) {
                axes = renderer.resources().buffer("acrossLines").read<std::uint32_t>();
            }
            const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloud.origin);
            int acrossWins = 0;
            for (std::size_t pixel = 0; pixel < reference.winner.size(); ++pixel) {
                const std::uint32_t winner = reference.winner[pixel];
                if (winner == kEmpty) {
                    continue;
                }
                double expected = 1.0;
                if (local) {
                    // The first-order projection of the across vector (RasterizePoints.comp).
                    const glm::dvec3 p(viewFromCloud *
                                       glm::dvec4(glm::dvec3(cloud.positions[winner]), 1.0));
                    const glm::dvec3 a =
                        glm::dmat3(viewFromCloud) * glm::dvec3(glm::vec3(spacing[winner]));
                    const glm::dvec2 moved = glm::dvec2(a) + glm::dvec2(p) * (a.z / -p.z);
                    const double across = glm::length(moved);
                    const double w = spacing[winner].w;
                    expected = std::max<double>(w, across);
                    acrossWins += across > w;
                    // "acrossLines": the doubled-angle axis of the projected vector, of length
                    // 1 - w / |vector|, where it is longer than w.
                    const glm::dvec2 axis = across > w
                                                ? glm::dvec2(moved.x * moved.x - moved.y * moved.y,
                                                             2.0 * moved.x * moved.y) *
                                                      ((1.0 - w / across) / (across * across))
                                                : glm::dvec2(0.0);
                    const glm::vec2 stored = glm::unpackHalf2x16(axes[pixel]);
                    // Half floats: 11 significant bits of values up to 1.
                    EXPECT_NEAR(stored.x, axis.x, 1e-3) << pixel;
                    EXPECT_NEAR(stored.y, axis.y, 1e-3) << pixel;
                }
                // RGBA16F: 11 significant bits; the float evaluation adds ~1e-6.
                EXPECT_NEAR(color[4 * pixel + 3], expected, 1e-3 * expected) << pixel;
            }
            if (local) {
                EXPECT_GT(acrossWins, 100);  // both terms of the maximum decide somewhere
            }
        }
    }
}

TEST_P(RasterPathGLTest, PointNormalsAreTheWinnersFacingTheEye) {
    GlContext& context = test::glTestContext();
    if (GetParam() == RasterPath::Int64 && !context.capabilities().int64Atomics) {
        GTEST_SKIP() << context.capabilities().renderer << " has no 64-bit atomics";
    }
    const Camera camera = smallCamera();
    PointCloud cloud = testCloud(camera, 3);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    giveRandomNormals(cloud, 6);
    for (const std::size_t chunk : {std::size_t{0}, std::size_t{97}}) {
        SCOPED_TRACE(chunk ? "chunks of 97" : "one chunk");
        Renderer renderer(context, cloud, std::nullopt, chunk);
        ASSERT_TRUE(renderer.gpuCloud().hasNormals());
        RenderSettings settings;
        settings.raster.path = GetParam();
        settings.raster.mode = RenderMode::Surface;
        settings.raster.normalBlend = 0.0f;  // the winner's own normal
        renderer.render(camera, settings, FrameOutputs::Everything);
        const std::vector<float> normals =
            renderer.resources().texture("pointNormals").readFloats();
        const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloud.origin);
        int flipped = 0, none = 0;
        for (std::size_t pixel = 0; pixel < reference.winner.size(); ++pixel) {
            const std::uint32_t winner = reference.winner[pixel];
            if (winner == kEmpty) {
                continue;
            }
            const glm::dvec3 p(viewFromCloud *
                               glm::dvec4(glm::dvec3(cloud.positions[winner]), 1.0));
            glm::dvec3 expected = glm::dmat3(viewFromCloud) *
                                  glm::dvec3(unpackNormal(packNormal(cloud.normals[winner])));
            if (glm::dot(expected, -p) < 0.0) {
                expected = -expected;
                ++flipped;
            }
            none += cloud.normals[winner] == glm::vec3(0.0f);
            for (int c = 0; c < 3; ++c) {
                // RGBA16F: 11 significant bits of a component up to 1.
                EXPECT_NEAR(normals[4 * pixel + c], expected[c], 1e-3) << pixel;
            }
        }
        EXPECT_GT(flipped, 100);  // both orientations occur
        EXPECT_GT(none, 20);      // and points without a normal
    }
}

TEST_P(RasterPathGLTest, NormalBlendAveragesTheNormalsNearTheNearest) {
    // Per pixel: the normalised sum of the normals (each facing the eye, weighted by its
    // cosine towards the eye) of the points within raster.normalBlend pixel widths behind the
    // nearest, at the nearest's depth. 10 pixel widths are 0.4 m at 1 m and 2 m at 5 m, so
    // some of a pixel's ~4 points, spread over 4.5 m, fall inside and some outside. The
    // colour blend alongside takes the same stage's other sums.
    GlContext& context = test::glTestContext();
    if (GetParam() == RasterPath::Int64 && !context.capabilities().int64Atomics) {
        GTEST_SKIP() << context.capabilities().renderer << " has no 64-bit atomics";
    }
    const Camera camera = smallCamera();
    PointCloud cloud = testCloud(camera, 4);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    giveRandomNormals(cloud, 9);
    constexpr float kBlend = 10.0f;
    constexpr float kColorBlend = 0.02f;
    const double focal = camera.focalLengthPixels();
    const std::size_t pixels = reference.winner.size();
    BlendSums normals{std::vector<glm::dvec3>(pixels, glm::dvec3(0.0)),
                      std::vector<int>(pixels, 0)};
    std::vector<int> inPixel(pixels, 0);
    const glm::dmat3 viewFromCloud(camera.viewFromCloud(cloud.origin));
    forEachPointOnScreen(cloud, camera, [&](std::uint32_t i, glm::dvec3 view, std::size_t pixel) {
        ++inPixel[pixel];
        const double edge = reference.depth[pixel] * (1.0 + kBlend / focal);
        // The GPU compares float depths: no point may lie within their rounding of the edge.
        ASSERT_GT(std::abs(-view.z - edge), 1e-5 * edge) << "point " << i;
        if (-view.z <= edge) {
            const glm::dvec3 normal =
                viewFromCloud * glm::dvec3(unpackNormal(packNormal(cloud.normals[i])));
            const double cosine = glm::dot(normal, glm::normalize(-view));
            normals.sums[pixel] += std::abs(cosine) * (cosine < 0.0 ? -normal : normal);
            ++normals.counts[pixel];
        }
    });
    int windowed = 0;
    for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
        windowed += normals.counts[pixel] >= 1 && normals.counts[pixel] < inPixel[pixel] ? 1 : 0;
    }
    ASSERT_GT(normals.pixelsOfSeveral(), 20) << "the test should blend pixels of several points";
    ASSERT_GT(windowed, 20) << "the test should leave points beyond the window out";
    const BlendSums colors = blendColorsOnCpu(cloud, camera, reference, kColorBlend);

    for (const std::size_t chunk : {std::size_t{0}, std::size_t{97}}) {
        Renderer renderer(context, cloud, std::nullopt, chunk);
        for (const float colorBlend : {0.0f, kColorBlend}) {
            SCOPED_TRACE(fmt::format("{}, {}", chunk ? "chunks of 97" : "one chunk",
                                     colorBlend > 0.0f ? "colours blended too" : "normals only"));
            RenderSettings settings;
            settings.raster.path = GetParam();
            settings.raster.mode = RenderMode::Surface;
            settings.raster.normalBlend = kBlend;
            settings.raster.colorBlend = colorBlend;
            renderer.render(camera, settings, FrameOutputs::Everything);
            const std::vector<float> image =
                renderer.resources().texture("pointNormals").readFloats();
            for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
                const int count = normals.counts[pixel];
                if (count == 0) {
                    continue;
                }
                const double length = glm::length(normals.sums[pixel]);
                const glm::dvec3 expected =
                    length > 0.0 ? normals.sums[pixel] / length : glm::dvec3(0.0);
                // RGBA16F's 11 significant bits (1e-3), plus the fixed point: each component of
                // each normal summed rounds by up to half of 1/4096, an error E of the sum S
                // that turns its normalised direction by at most 2 |E| / |S|.
                const double tolerance =
                    1e-3 + (length > 0.0 ? 2.0 * count * std::sqrt(3.0) * 0.5 / 4096 / length : 0);
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(image[4 * pixel + c], expected[c], tolerance)
                        << "pixel " << pixel << " of " << count << " points";
                }
            }
            if (colorBlend > 0.0f) {
                expectBlendedColors(renderer, reference, colors);
            }
        }
    }
}

TEST(RasterizePointsGLTest, PackedNormalsKeepTheirDirection) {
    // The octahedral map's snorm16 grid is ~3e-5 wide: every direction within 0.01 degrees.
    std::mt19937 random(8);
    std::normal_distribution<float> gauss(0.0f, 1.0f);
    double worst = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 n = glm::normalize(glm::vec3(gauss(random), gauss(random), gauss(random)));
        const glm::dvec3 back(unpackNormal(packNormal(n)));
        // The angle from the cross product: acos loses it near 1.
        worst =
            std::max(worst, std::asin(std::min(1.0, glm::length(glm::cross(glm::dvec3(n), back)))));
    }
    EXPECT_LT(worst, 0.01 * std::numbers::pi / 180.0);
    for (const glm::vec3& axis :
         {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0)}) {
        EXPECT_NE(packNormal(axis), 0u);  // 0 means "no normal"
        EXPECT_LT(glm::length(unpackNormal(packNormal(axis)) - axis), 1e-4f);
    }
    EXPECT_EQ(packNormal(glm::vec3(0.0f)), 0u);
    EXPECT_EQ(packNormal(glm::vec3(std::nanf(""), 0.0f, 1.0f)), 0u);
    EXPECT_EQ(unpackNormal(0u), glm::vec3(0.0f));
}

TEST(RasterizePointsGLTest, PackedLocalSpacingKeepsItsValuesAndSkipsTheSparsest) {
    // 1,000 points: the ratio that 99.9 % stay within ignores one sparse point, not two.
    std::vector<glm::vec4> spacing(1000, glm::vec4(0.0f, 0.0f, 0.0f, 1.5f));
    spacing[10] = glm::vec4(0.0f, 0.0f, 0.0f, 40.0f);
    EXPECT_EQ(packLocalSpacing(spacing).sparseSpacingRatio, 1.5f);
    // Along an across vector (3, 4, 0): its length, 5, beats w; below 1 the ratio is 1.
    spacing[20] = glm::vec4(3.0f, 4.0f, 0.0f, 2.0f);
    for (glm::vec4& entry : spacing) {
        entry.w = std::min(entry.w, 0.5f);
    }
    spacing[10].w = 40.0f;
    const PackedLocalSpacing packed = packLocalSpacing(spacing);
    EXPECT_EQ(packed.sparseSpacingRatio, 5.0f);
    spacing[10].w = 0.5f;
    EXPECT_EQ(packLocalSpacing(spacing).sparseSpacingRatio, 1.0f);
    ASSERT_EQ(packed.halves.size(), spacing.size());
    // Half floats hold these values exactly.
    EXPECT_EQ(glm::unpackHalf(packed.halves[20]), glm::vec4(3.0f, 4.0f, 0.0f, 0.5f));
    EXPECT_EQ(glm::unpackHalf(packed.halves[10]), glm::vec4(0.0f, 0.0f, 0.0f, 40.0f));
    EXPECT_TRUE(packLocalSpacing({}).halves.empty());
}

INSTANTIATE_TEST_SUITE_P(RasterizePointsGLTest, RasterPathGLTest,
                         ::testing::Values(RasterPath::TwoPass32, RasterPath::Int64),
                         [](const ::testing::TestParamInfo<RasterPath>& tested) {
                             return tested.param == RasterPath::Int64 ? "Int64" : "TwoPass32";
                         });

TEST(RasterizePointsGLTest, ColorBlendAveragesThePointsNearTheNearest) {
    // Per pixel: the mean linear colour of the points whose depth is within 2 % of the
    // nearest's (the test cloud's depths lie 1.5 mm apart from 1 m on, so several share a
    // pixel's band and none sits within float rounding of its edge), the depth unchanged.
    GlContext& context = test::glTestContext();
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 2);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    constexpr float kBlend = 0.02f;
    const BlendSums expected = blendColorsOnCpu(cloud, camera, reference, kBlend);
    EXPECT_GT(expected.pixelsOfSeveral(), 20) << "the test should blend pixels of several points";

    Renderer renderer(context, cloud);
    RenderSettings settings;
    settings.raster.colorBlend = kBlend;
    renderer.render(camera, settings);
    expectBlendedColors(renderer, reference, expected);
}

TEST(RasterizePointsGLTest, AFarFrameAfterACloseOneKeepsNothingOfIt) {
    // The resolve visits only the pixels the cloud's bounding box projects to: the rest must
    // still be empty, not what the frame before left there.
    GlContext& context = test::glTestContext();
    const Camera close = smallCamera();
    const PointCloud cloud = testCloud(close, 2);
    Camera far = close;
    far.farPlane = 60.0;
    far.view = glm::lookAt(glm::dvec3(0.3, -0.2, 30.0), glm::dvec3(0.0), glm::dvec3(0, 1, 0));
    const glm::ivec4 box = projectedPixelBounds(far, cloud.bounds);
    ASSERT_LT((box.z - box.x) * (box.w - box.y), far.width * far.height / 2);

    Renderer renderer(context, cloud);
    RenderSettings settings;
    settings.raster.path = RasterPath::TwoPass32;
    renderer.render(close, settings);
    renderer.render(far, settings);
    // The far view still shows the cloud.
    EXPECT_GT(expectMatchesReference(renderer, cloud, rasterizeOnCpu(cloud, far)), 10u);
}

TEST(RasterizePointsGLTest, ForcingInt64WithoutSupportIsAClearError) {
    GlContext& context = test::glTestContext();
    if (context.capabilities().int64Atomics) {
        GTEST_SKIP() << "this driver has 64-bit atomics";
    }
    const Camera camera = smallCamera();
    Renderer renderer(context, testCloud(camera, 2));
    RenderSettings settings;
    settings.raster.path = RasterPath::Int64;
    EXPECT_THROW(renderer.render(camera, settings), Error);
}

TEST(RasterizePointsGLTest, SplatsShowTheNearestPointWhoseSquareCoversThePixel) {
    // GL_POINTS of 3 pixels: a point lying 0.2..0.8 into its pixel covers exactly the 3x3
    // pixels around it (their centres lie 0.7 px or more inside its square), and the depth test
    // keeps the nearest of the covering points, the first drawn (smaller index) on a tie.
    GlContext& context = test::glTestContext();
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 4);
    const Reference centres = rasterizeOnCpu(cloud, camera);
    std::vector<std::uint32_t> winner(centres.winner.size(), kEmpty);
    std::vector<double> nearest(centres.winner.size(), std::numeric_limits<double>::infinity());
    const glm::dmat4 viewFromCloud = camera.viewFromCloud(cloud.origin);
    const glm::dmat4 projection = camera.projection();
    for (std::uint32_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec4 view = viewFromCloud * glm::dvec4(glm::dvec3(cloud.positions[i]), 1.0);
        const glm::dvec4 clip = projection * view;
        const int px = static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * camera.width));
        const int py = static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * camera.height));
        if (-view.z < camera.nearPlane || -view.z > camera.farPlane || px < 0 || py < 0 ||
            px >= camera.width || py >= camera.height) {
            continue;  // GL discards a point whose centre is outside the view volume
        }
        for (int y = std::max(py - 1, 0); y <= std::min(py + 1, camera.height - 1); ++y) {
            for (int x = std::max(px - 1, 0); x <= std::min(px + 1, camera.width - 1); ++x) {
                const std::size_t pixel = static_cast<std::size_t>(y) * camera.width + x;
                if (-view.z < nearest[pixel]) {
                    nearest[pixel] = -view.z;
                    winner[pixel] = i;
                }
            }
        }
    }

    Renderer renderer(context, cloud, std::nullopt, 500);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Splats;
    settings.raster.pointSize = 3.0f;
    renderer.render(camera, settings);
    const std::vector<float> depth = renderer.resources().texture("depth").readFloats();
    const std::vector<float> color = renderer.resources().texture("color").readFloats();
    std::size_t covered = 0;
    for (std::size_t pixel = 0; pixel < winner.size(); ++pixel) {
        if (winner[pixel] == kEmpty) {
            EXPECT_TRUE(std::isinf(depth[pixel])) << "pixel " << pixel;
            continue;
        }
        ++covered;
        // Same float transform as the compute path: ~1e-6 relative.
        EXPECT_NEAR(depth[pixel], nearest[pixel], 1e-5 * nearest[pixel]) << "pixel " << pixel;
        const Rgba8 expected = cloud.colors[winner[pixel]];
        const std::uint8_t channels[3] = {expected.r, expected.g, expected.b};
        for (int c = 0; c < 3; ++c) {
            // RGBA16F keeps 11 significant bits: 1e-3 relative, plus the sRGB curve's rounding.
            EXPECT_NEAR(color[4 * pixel + c], srgbToLinear(channels[c] / 255.0f), 2e-3)
                << "pixel " << pixel;
        }
    }
    EXPECT_GT(covered, winner.size() * 9 / 10) << "3-pixel splats of this cloud cover nearly all";
}

TEST(RasterizePointsGLTest, GlPointsBaselineSeesTheSameNearestPoints) {
    GlContext& context = test::glTestContext();
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 3);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    Renderer renderer(context, cloud, std::nullopt, 500);
    RenderSettings settings;
    settings.raster.mode = RenderMode::PointsGl;
    renderer.render(camera, settings);
    const std::vector<float> depth = renderer.resources().texture("depth").readFloats();
    const std::vector<float> color = renderer.resources().texture("color").readFloats();
    for (std::size_t pixel = 0; pixel < reference.depth.size(); ++pixel) {
        if (std::isinf(reference.depth[pixel])) {
            EXPECT_TRUE(std::isinf(depth[pixel])) << "pixel " << pixel;
            continue;
        }
        // Same float transform as the compute path: ~1e-6 relative.
        EXPECT_NEAR(depth[pixel], reference.depth[pixel], 1e-5 * reference.depth[pixel])
            << "pixel " << pixel;
        // The nearest point's colour; an exact duplicate (its own random colour) drawn later
        // fails GL_LESS, as the smaller index wins in the reference.
        const Rgba8 expected = cloud.colors[reference.winner[pixel]];
        const std::uint8_t channels[3] = {expected.r, expected.g, expected.b};
        for (int c = 0; c < 3; ++c) {
            // RGBA16F keeps 11 significant bits: 1e-3 relative, plus the sRGB curve's rounding.
            EXPECT_NEAR(color[4 * pixel + c], srgbToLinear(channels[c] / 255.0f), 2e-3)
                << "pixel " << pixel;
        }
    }
}

TEST(RasterizePointsGLTest, SplatsCoverTheirSquare) {
    GlContext& context = test::glTestContext();
    Camera camera = smallCamera();
    PointCloudBuilder builder({}, 1);
    builder.add({pointAtPixel(camera, 18.5, 11.5, 4.0)});
    std::vector<std::string> warnings;
    Renderer renderer(context, builder.finish(warnings));
    RenderSettings settings;
    settings.raster.mode = RenderMode::Splats;
    settings.raster.pointSize = 5.0f;
    renderer.render(camera, settings);
    const std::vector<float> depth = renderer.resources().texture("depth").readFloats();
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const bool inside = std::abs(x - 18) <= 2 && std::abs(y - 11) <= 2;
            EXPECT_EQ(std::isfinite(depth[y * camera.width + x]), inside) << x << "," << y;
        }
    }
}

TEST(RasterizePointsGLTest, PresentEncodesSrgbAndFillsTheBackground) {
    GlContext& context = test::glTestContext();
    const Camera camera = smallCamera();
    const PointCloud cloud = testCloud(camera, 4);
    const Reference reference = rasterizeOnCpu(cloud, camera);
    Renderer renderer(context, cloud);
    RenderSettings settings;
    settings.raster.backgroundSrgb = {0.2f, 0.4f, 0.6f};
    renderer.render(camera, settings);
    const std::vector<std::uint8_t> image = renderer.readImage();
    for (std::size_t pixel = 0; pixel < reference.winner.size(); ++pixel) {
        std::uint8_t expected[3] = {51, 102, 153};  // the background, 0.2/0.4/0.6 of 255
        if (reference.winner[pixel] != kEmpty) {
            const Rgba8 c = cloud.colors[reference.winner[pixel]];
            expected[0] = c.r;
            expected[1] = c.g;
            expected[2] = c.b;
        }
        for (int c = 0; c < 3; ++c) {
            // sRGB -> linear half float -> sRGB round-trips within one 8-bit step.
            EXPECT_NEAR(image[4 * pixel + c], expected[c], 1) << "pixel " << pixel;
        }
        EXPECT_EQ(image[4 * pixel + 3], 255);
    }
}

}  // namespace
}  // namespace subscan
