// TemporalPass: the previous result reprojected by depth and both cameras (against a CPU
// reference of the same formula), disocclusion, the even mean of a still camera, and end to end
// through the Renderer: jittered frames converge to the supersampled coverage of an edge, and a
// fast move leaves no ghost once the camera stops.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/PointCloud.h"
#include "core/Srgb.h"
#include "render/Renderer.h"
#include "render/TemporalPass.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"
#include "support/PassHarness.h"

namespace subscan {
namespace {

constexpr int kWidth = 48;
constexpr int kHeight = 40;
constexpr double kSpacing = 0.05;  // the point spacing the harness's frames assume

/// A tilted plane in front of the harness's first camera.
struct Plane {
    glm::dvec3 point{0.0, 0.0, -5.0};
    glm::dvec3 normal = glm::normalize(glm::dvec3(0.15, 0.1, 1.0));

    /// Where the ray from the eye of `camera` through window position `window` (viewRay)
    /// meets the plane, in world (= the harness's cloud) coordinates.
    glm::dvec3 hit(const Camera& camera, glm::dvec2 window) const;
};

/// The direction, in view space, of the ray from the eye of `camera` through window position
/// `window`, of length 1 along the view axis: built from the camera's lens and jitter as the
/// definition of a pinhole, independent of the shaders' helpers.
glm::dvec3 viewRay(const Camera& camera, glm::dvec2 window) {
    const double f = camera.focalLengthPixels();
    const glm::dvec2 shifted = window - camera.jitterPixels;
    return {(shifted.x - 0.5 * camera.width) / f, (0.5 * camera.height - shifted.y) / f, -1.0};
}

glm::dvec3 Plane::hit(const Camera& camera, glm::dvec2 window) const {
    const glm::dvec3 direction = viewRay(camera, window);
    const glm::dmat4 toWorld = glm::inverse(camera.view);
    const glm::dvec3 eye(toWorld * glm::dvec4(0, 0, 0, 1));
    const glm::dvec3 ray(toWorld * glm::dvec4(direction, 0.0));
    const double t = glm::dot(point - eye, normal) / glm::dot(ray, normal);
    return eye + t * ray;
}

/// The world point `camera` sees at window position `window` and linear depth `depth`.
glm::dvec3 worldAt(const Camera& camera, glm::dvec2 window, double depth) {
    return glm::dvec3(glm::inverse(camera.view) * glm::dvec4(depth * viewRay(camera, window), 1.0));
}

double linearDepth(const Camera& camera, const glm::dvec3& world) {
    return -(camera.view * glm::dvec4(world, 1.0)).z;
}

/// The un-jittered window position of a world point.
glm::dvec2 windowOf(const Camera& camera, const glm::dvec3& world) {
    Camera plain = camera;
    plain.jitterPixels = glm::dvec2(0.0);
    const glm::dvec4 clip = plain.projection() * camera.view * glm::dvec4(world, 1.0);
    return {(clip.x / clip.w + 1.0) * 0.5 * camera.width,
            (1.0 - clip.y / clip.w) * 0.5 * camera.height};
}

/// A colour anchored to the plane, so that reprojection errors change it.
glm::vec3 pattern(const glm::dvec3& world) {
    return glm::vec3(0.5 + 0.4 * std::sin(3.0 * world.x), 0.5 + 0.4 * std::cos(2.0 * world.y),
                     0.3 + 0.1 * world.x);
}

struct Inputs {
    std::vector<float> radiance;  // RGBA
    std::vector<float> depth;
    std::vector<float> coverage;  // OutlineCoverage's share per pixel; empty: the mask's
};

/// The plane seen through `camera`: colour from `colorOf(world, x, y)`, +inf where `hole`.
template <class Color, class Hole>
Inputs planeInputs(const Camera& camera, const Plane& plane, Color colorOf, Hole hole) {
    Inputs inputs;
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const glm::dvec3 world = plane.hit(camera, {x + 0.5, y + 0.5});
            const glm::vec3 color = colorOf(world, x, y);
            inputs.radiance.insert(inputs.radiance.end(), {color.r, color.g, color.b, 1.0f});
            inputs.depth.push_back(hole(x, y) ? INFINITY
                                              : static_cast<float>(linearDepth(camera, world)));
        }
    }
    return inputs;
}

/// TemporalPass alone, fed as the per-pass chain feeds it ("radiance" and "surfaceDepth") or
/// as FinishSurface does ("radianceAndDepth").
class TemporalHarness {
  public:
    explicit TemporalHarness(const RenderSettings& settings, double spacing = kSpacing,
                             TemporalDepth depth = TemporalDepth::SurfaceDepth)
        : harness_(kWidth, kHeight, settings, spacing),
          pass_(harness_.sources(), history_),
          depth_(depth) {
        pass_.setInput(depth == TemporalDepth::ColorAlpha ? "radianceAndDepth" : "radiance", depth,
                       false);
    }

    const Camera& camera() const { return harness_.camera(); }

    /// One frame of the filter; returns "history" (RGBA) and "historyState" (depth, count).
    std::pair<std::vector<float>, std::vector<float>> run(const Camera& camera,
                                                          const Inputs& inputs) {
        harness_.setCamera(camera);
        FrameResources& resources = harness_.resources();
        if (depth_ == TemporalDepth::ColorAlpha) {
            std::vector<float> packed = inputs.radiance;
            for (std::size_t i = 0; i < inputs.depth.size(); ++i) {
                packed[4 * i + 3] = inputs.depth[i];
            }
            resources.ensureTexture("radianceAndDepth", TextureFormat::RGBA32F, kWidth, kHeight)
                .uploadFloats(packed);
        } else {
            // OutlineCoverage's alpha: the covered share, where the inputs do not give one
            // the mask's.
            std::vector<float> radiance = inputs.radiance;
            for (std::size_t i = 0; i < inputs.depth.size(); ++i) {
                radiance[4 * i + 3] = !inputs.coverage.empty()      ? inputs.coverage[i]
                                      : std::isinf(inputs.depth[i]) ? 0.0f
                                                                    : 1.0f;
            }
            resources.ensureTexture("radiance", TextureFormat::RGBA16F, kWidth, kHeight)
                .uploadFloats(radiance);
            resources.ensureTexture("surfaceDepth", TextureFormat::R32F, kWidth, kHeight)
                .uploadFloats(inputs.depth);
        }
        FrameContext frame = harness_.context();
        pass_.execute(frame);
        return {resources.texture("history").readFloats(),
                resources.texture("historyState").readFloats()};
    }

  private:
    test::PassHarness harness_;
    TemporalHistory history_;
    TemporalPass pass_;
    TemporalDepth depth_;
};

// The two ways the filter gets the frame's depth: each test of the pass alone runs both.
const TemporalDepth kDepthSources[] = {TemporalDepth::SurfaceDepth, TemporalDepth::ColorAlpha};

const char* describe(TemporalDepth depth) {
    return depth == TemporalDepth::SurfaceDepth ? "depth from surfaceDepth"
                                                : "depth in the colour's alpha";
}

/// Four colours by the parities of x and y: a neighbourhood whose luma and both chromas spread
/// over most of 0..1, so that clipping to it (with a wide sigma) keeps any history of 0..1.
glm::vec3 checker(glm::dvec3, int x, int y) {
    return glm::vec3(float((x + y) % 2), float(x % 2), float(y % 2));
}

/// `camera` moved sideways by `fraction` of the cloud's width: the picture pans across.
Camera pannedAcross(Camera camera, const PointCloud& cloud, double fraction) {
    camera.view =
        glm::translate(glm::dmat4(1.0), glm::dvec3(fraction * cloud.bounds.extent().x, 0, 0)) *
        camera.view;
    return camera;
}

/// A second camera turned and moved against the harness's, both jittered differently.
Camera movedCamera(const Camera& first) {
    Camera moved = first;
    moved.view = glm::translate(
        glm::rotate(glm::dmat4(1.0), glm::radians(2.0), glm::normalize(glm::dvec3(0.3, 1.0, 0.1))),
        glm::dvec3(-0.12, 0.05, 0.1));
    moved.jitterPixels = {0.25, -0.3};
    return moved;
}

TEST(TemporalGLTest, ReprojectsTheHistoryLikeTheCpuReference) {
    RenderSettings settings;
    settings.temporal.enabled = true;
    settings.temporal.newFrameWeight = 0.01f;
    // Clipping far outside the new frame's spread: this test is about where the history comes
    // from, not about how it is clipped.
    settings.temporal.clipSigma = 100.0f;
    for (const TemporalDepth depth : kDepthSources) {
        SCOPED_TRACE(describe(depth));
        TemporalHarness harness(settings, kSpacing, depth);
        const Plane plane;
        Camera first = harness.camera();
        first.jitterPixels = {-0.2, 0.35};
        const Camera second = movedCamera(first);
        auto none = [](int, int) { return false; };

        const auto [history1, state1] = harness.run(
            first, planeInputs(
                       first, plane, [](glm::dvec3 w, int, int) { return pattern(w); }, none));
        // Bumps: a fifth of the pixels lie 40 % nearer, so which neighbour is nearest decides
        // where the history comes from. No tap is dropped: a tap is kept within 4 spacings
        // plus the neighbourhood's depth range of the depth it kept, and the range spans the
        // bump.
        Inputs secondInputs = planeInputs(second, plane, checker, none);
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                if ((7 * x + 13 * y) % 5 == 0) {
                    secondInputs.depth[y * kWidth + x] *= 0.6f;
                }
            }
        }
        const auto [history2, state2] = harness.run(second, secondInputs);

        int compared = 0, reprojected = 0;
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                // The neighbour with the nearest depth stands for the pixel's motion (first of
                // equals in row order, borders clamped), as in the shader.
                glm::ivec2 nearest(x, y);
                float nearestDepth = INFINITY;
                for (int i = 0; i < 9; ++i) {
                    const glm::ivec2 t =
                        glm::clamp(glm::ivec2(x + i % 3 - 1, y + i / 3 - 1), glm::ivec2(0),
                                   glm::ivec2(kWidth - 1, kHeight - 1));
                    const float d = secondInputs.depth[t.y * kWidth + t.x];
                    if (d < nearestDepth) {
                        nearestDepth = d;
                        nearest = t;
                    }
                }
                const glm::dvec3 world = worldAt(second, glm::dvec2(nearest) + 0.5, nearestDepth);
                const glm::dvec2 velocity =
                    windowOf(first, world) - (glm::dvec2(nearest) + 0.5 - second.jitterPixels);
                const glm::dvec2 source = glm::dvec2(x, y) + velocity;
                const glm::ivec2 base(glm::floor(source));
                const glm::dvec2 t = source - glm::dvec2(base);
                glm::dvec4 sum(0.0);
                double weights = 0.0;
                for (int tap = 0; tap < 4; ++tap) {
                    const glm::ivec2 texel = base + glm::ivec2(tap & 1, tap >> 1);
                    if (texel.x < 0 || texel.y < 0 || texel.x >= kWidth || texel.y >= kHeight) {
                        continue;
                    }
                    const std::size_t i = 4 * static_cast<std::size_t>(texel.y * kWidth + texel.x);
                    const double w = ((tap & 1) ? t.x : 1.0 - t.x) * ((tap >> 1) ? t.y : 1.0 - t.y);
                    sum += w * glm::dvec4(history1[i], history1[i + 1], history1[i + 2],
                                          history1[i + 3]);
                    weights += w;
                }
                const std::size_t i = 4 * static_cast<std::size_t>(y * kWidth + x);
                const glm::dvec4 current(secondInputs.radiance[i], secondInputs.radiance[i + 1],
                                         secondInputs.radiance[i + 2], 1.0);
                // Each history holds one frame: the new one weighs 1/2.
                const glm::dvec4 expected =
                    weights > 0.1 ? 0.5 * (sum / weights) + 0.5 * current : current;
                reprojected += weights > 0.1 ? 1 : 0;
                for (int c = 0; c < 4; ++c) {
                    // Half-float storage of the result: 2^-11 relative, and the pattern is <= 1.
                    EXPECT_NEAR(history2[i + c], expected[c], 2e-3)
                        << "pixel " << x << "," << y << " channel " << c;
                }
                ++compared;
            }
        }
        EXPECT_EQ(compared, kWidth * kHeight);
        EXPECT_GT(reprojected, compared * 3 / 4) << "the move should keep most of the view";
        EXPECT_LT(reprojected, compared) << "the move should uncover a border";
    }
}

TEST(TemporalGLTest, DropsHistoryThatSawAnotherSurface) {
    RenderSettings settings;
    settings.temporal.enabled = true;
    settings.temporal.clipSigma = 100.0f;  // as above: only disocclusion may drop the history
    for (const TemporalDepth depth : kDepthSources) {
        SCOPED_TRACE(describe(depth));
        TemporalHarness harness(settings, kSpacing, depth);
        const Plane plane;
        const Camera first = harness.camera();
        const Camera second = movedCamera(first);
        // The first frame has an object in front (1 m nearer) over the left half; the second sees
        // the plane everywhere, so the left half's history belongs to another surface.
        Inputs occluded = planeInputs(
            first, plane, [](glm::dvec3, int, int) { return glm::vec3(1.0f, 0.0f, 0.0f); },
            [](int, int) { return false; });
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth / 2; ++x) {
                occluded.depth[y * kWidth + x] -= 1.0f;
            }
        }
        harness.run(first, occluded);
        const Inputs plain = planeInputs(second, plane, checker, [](int, int) { return false; });
        const auto [history, state] = harness.run(second, plain);
        int blended = 0;
        for (int y = 4; y < kHeight - 4; ++y) {
            for (int x = 4; x < kWidth - 4; ++x) {
                const std::size_t i = static_cast<std::size_t>(y * kWidth + x);
                const float red = plain.radiance[4 * i];
                if (x < kWidth / 2 - 8) {
                    // Well inside the left half (the move shifts it by a few pixels): the frame
                    // alone, none of the occluder's red.
                    EXPECT_EQ(history[4 * i], red) << "at " << x << "," << y;
                    EXPECT_EQ(state[2 * i + 1], 1.0f) << "frames at " << x << "," << y;
                } else if (x > kWidth / 2 + 8) {
                    // The same surface: the occluder-free history (red 1) blended in at 1/2.
                    EXPECT_NEAR(history[4 * i], 0.5f * (1.0f + red), 1e-3)  // half floats
                        << "at " << x << "," << y;
                    ++blended;
                }
            }
        }
        EXPECT_GT(blended, 0);
    }
}

TEST(TemporalGLTest, ClipsTheHistoryToTheNewFramesNeighbourhood) {
    // A moving camera whose history (red) falls outside everything the new frame shows
    // nearby (blue, no spread): clipping moves it onto the new frame's colour, as it would a
    // ghost of a surface that has left.
    RenderSettings settings;
    settings.temporal.enabled = true;
    for (const TemporalDepth depth : kDepthSources) {
        SCOPED_TRACE(describe(depth));
        TemporalHarness harness(settings, kSpacing, depth);
        const Plane plane;
        const Camera first = harness.camera();
        auto none = [](int, int) { return false; };
        harness.run(first, planeInputs(
                               first, plane,
                               [](glm::dvec3, int, int) { return glm::vec3(1, 0, 0); }, none));
        const auto [history, state] = harness.run(
            movedCamera(first), planeInputs(
                                    movedCamera(first), plane,
                                    [](glm::dvec3, int, int) { return glm::vec3(0, 0, 1); }, none));
        for (std::size_t i = 0; i < history.size(); i += 4) {
            EXPECT_NEAR(history[i], 0.0f, 1e-3) << "texel " << i / 4;  // half-float rounding
            EXPECT_NEAR(history[i + 2], 1.0f, 1e-3) << "texel " << i / 4;
        }
    }
}

TEST(TemporalGLTest, StillCameraAveragesEvenlyAndBackgroundCountsAsUncovered) {
    RenderSettings settings;
    settings.temporal.enabled = true;
    settings.temporal.maxFrames = 4;
    for (const TemporalDepth depth : kDepthSources) {
        SCOPED_TRACE(describe(depth));
        TemporalHarness harness(settings, kSpacing, depth);
        const Plane plane;
        const Camera camera = harness.camera();
        // Frames 1..6 show 0.1 k; the left column is background in odd frames. With a still
        // camera the mean is even over the last frames up to 4, then slides by 1/4.
        std::vector<float> history;
        double expected = 0.0, coverage = 0.0, left = 0.0;
        const double background = srgbToLinear(settings.raster.backgroundSrgb.r);
        for (int k = 1; k <= 6; ++k) {
            Camera jittered = camera;
            jittered.jitterPixels = haltonJitter(static_cast<unsigned>(k));
            const float value = 0.1f * static_cast<float>(k);
            const bool hole = k % 2 == 1;
            history = harness
                          .run(jittered, planeInputs(
                                             jittered, plane,
                                             [&](glm::dvec3, int, int) { return glm::vec3(value); },
                                             [&](int x, int) { return hole && x == 0; }))
                          .first;
            const double weight = 1.0 / std::min(k, 4);
            expected += weight * (value - expected);
            left += weight * ((hole ? background : value) - left);
            coverage += weight * ((hole ? 0.0 : 1.0) - coverage);
            const std::size_t middle =
                4 * static_cast<std::size_t>(kHeight / 2 * kWidth + kWidth / 2);
            const std::size_t edge = 4 * static_cast<std::size_t>(kHeight / 2 * kWidth);
            // Half floats: 2^-11 relative on values below 1.
            EXPECT_NEAR(history[middle], expected, 1e-3) << "frame " << k;
            EXPECT_NEAR(history[edge], left, 1e-3) << "frame " << k;
            EXPECT_NEAR(history[edge + 3], coverage, 1e-3) << "frame " << k;
        }
    }
}

// ---- end to end, through the Renderer ----

/// A dense square of points, 2 x 2 units in the plane z = 0, `perSide` points per side.
PointCloud square(int perSide) {
    PointCloudBuilder builder({}, static_cast<std::size_t>(perSide * perSide));
    for (int j = 0; j < perSide; ++j) {
        for (int i = 0; i < perSide; ++i) {
            builder.add(
                {glm::dvec3(-1.0 + 2.0 * i / (perSide - 1), -1.0 + 2.0 * j / (perSide - 1), 0.0)});
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

TEST(TemporalGLTest, JitteredFramesConvergeToTheSupersampledCoverageOfAnEdge) {
    // The square seen face on, 32 pixels wide, its left and right edges 1/64 pixel past the
    // middle of pixels 8 and 40 (not exactly there, which would leave the outermost points to
    // rounding). A frame's pixel is surface when the jittered pixel centre lies inside the
    // outline the points' sub-pixel cells show (SurfaceSettings::subpixelOutline), so each
    // frame shows the edge pixels covered or not (error 0.5), and the mean over 16 Halton
    // offsets, whose x are 16 evenly spread values, is the fraction of offsets that put the
    // centre inside: 8/16 for both, against the true areas 31/64 and 33/64. Were every pixel
    // holding a point surface, pixel 8 would be covered in every frame.
    constexpr int kSize = 48;
    Camera camera;
    camera.width = kSize;
    camera.height = kSize;
    camera.fovyDegrees = 30.0;
    const double distance = 2.0 / (32.0 / camera.focalLengthPixels());  // 2 units = 32 px
    camera.nearPlane = 0.1;
    camera.farPlane = 10.0;
    const double pixel = distance / camera.focalLengthPixels();  // scene units per pixel
    camera.view =
        glm::translate(glm::dmat4(1.0), glm::dvec3((0.5 + 1.0 / 64.0) * pixel, 0.0, -distance));

    const PointCloud cloud = square(257);  // 8 points per pixel: every 4x4 cell holds points
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.temporal.enabled = true;
    // Along the edges, away from the corners: the two edge pixels of each row at 1/2, their
    // outer neighbours at 0 and inner ones at 1.
    const std::pair<int, double> expected[] = {{7, 0.0},  {8, 0.5},  {9, 1.0},
                                               {39, 1.0}, {40, 0.5}, {41, 0.0}};
    auto edgeError = [&](const std::vector<float>& coverage, bool edgesOnly) {
        double error = 0.0;
        int pixels = 0;
        for (int y = 10; y < 38; ++y) {
            for (const auto& [x, value] : expected) {
                if (!edgesOnly || value == 0.5) {
                    error += std::abs(coverage[y * kSize + x] - value);
                    ++pixels;
                }
            }
        }
        return error / pixels;
    };
    auto alphaOf = [&] {
        const std::vector<float> history = renderer.resources().texture("history").readFloats();
        std::vector<float> alpha;
        for (std::size_t i = 3; i < history.size(); i += 4) {
            alpha.push_back(history[i]);
        }
        return alpha;
    };
    renderer.render(camera, settings);
    const double oneFrame = edgeError(alphaOf(), true);
    for (int frame = 1; frame < 16; ++frame) {
        renderer.render(camera, settings);
    }
    const double sixteenFrames = edgeError(alphaOf(), false);
    EXPECT_GT(oneFrame, 0.45) << "one frame decides each edge pixel whole";
    // 8 of 16 exactly, up to the half-float result; points 1/8 pixel apart leave no room
    // for a miss.
    EXPECT_LT(sixteenFrames, 0.01) << "after one frame: " << oneFrame;
}

TEST(TemporalGLTest, OffTheSurfaceTheHistoryHoldsTheBackgroundWhereverTheRegionWent) {
    // The filter clears only what an earlier frame left outside this frame's region: pan a
    // small sphere across the picture (its region moves every frame), then far from this
    // frame's surface the history must be the background and its state "no surface", exactly.
    const PointCloud cloud = makeSyntheticScene("sphere");
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.temporal.enabled = true;
    constexpr int kSize = 96;
    auto poseAt = [&](double panFraction) {
        OrbitView orbit;
        orbit.distance = 4.0 * glm::length(cloud.bounds.extent());  // about 17 pixels across
        return pannedAcross(orbitCamera(cloud.bounds, orbit, kSize, kSize, 45.0), cloud,
                            panFraction);
    };
    for (int frame = 0; frame < 4; ++frame) {  // still: the history converges at one place
        renderer.render(poseAt(-1.5), settings);
    }
    for (int step = 1; step <= 7; ++step) {  // then it moves right, about 7 pixels a frame
        renderer.render(poseAt(-1.5 + 0.4 * step), settings, FrameOutputs::Everything);
    }
    const FrameResources& resources = renderer.resources();
    const std::vector<float> depth = resources.texture("surfaceDepth").readFloats();
    const std::vector<float> history = resources.texture("history").readFloats();
    const std::vector<float> state = resources.texture("historyState").readFloats();
    const glm::vec3& background = settings.raster.backgroundSrgb;
    const glm::vec3 linear(srgbToLinear(background.r), srgbToLinear(background.g),
                           srgbToLinear(background.b));
    int checked = 0, surface = 0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            // Two pixels from any surface: beyond what a blend of neighbours could reach.
            bool nearSurface = false;
            for (int dy = -2; dy <= 2; ++dy) {
                for (int dx = -2; dx <= 2; ++dx) {
                    const int qx = std::clamp(x + dx, 0, kSize - 1);
                    const int qy = std::clamp(y + dy, 0, kSize - 1);
                    nearSurface = nearSurface || std::isfinite(depth[qy * kSize + qx]);
                }
            }
            const int i = y * kSize + x;
            surface += std::isfinite(depth[i]);
            if (nearSurface) {
                continue;
            }
            ++checked;
            for (int c = 0; c < 3; ++c) {
                // A blend of the background with itself may round in the last bits; what an
                // earlier frame left would be the sphere's colour.
                ASSERT_NEAR(history[4 * i + c], linear[c], 1e-6f) << x << "," << y;
            }
            ASSERT_NEAR(history[4 * i + 3], 0.0f, 1e-6f) << x << "," << y;
            ASSERT_TRUE(std::isinf(state[2 * i])) << x << "," << y;
        }
    }
    // The sphere is in the picture (about 220 pixels), and small: the frames' regions, its
    // bounds and a margin, leave most of the picture to the clears.
    EXPECT_GT(surface, 100);
    EXPECT_LT(surface, kSize * kSize / 16);
    EXPECT_GT(checked, kSize * kSize / 2);
}

TEST(TemporalGLTest, AFastMoveLeavesNoGhostOnceTheCameraStops) {
    const PointCloud cloud = makeSyntheticScene("sphere");
    Renderer renderer(test::glTestContext(), cloud);
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.temporal.enabled = true;
    constexpr int kSize = 64;
    auto poseAt = [&](double yaw, double panFraction) {
        OrbitView orbit;
        orbit.yawDegrees = yaw;
        orbit.pitchDegrees = 10.0;
        // Panning sweeps the silhouette across the picture.
        return pannedAcross(orbitCamera(cloud.bounds, orbit, kSize, kSize, 45.0), cloud,
                            panFraction);
    };
    auto picture = [&] { return renderer.readImage(); };
    auto meanDifference = [](const std::vector<std::uint8_t>& a,
                             const std::vector<std::uint8_t>& b) {
        double sum = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            sum += std::abs(int(a[i]) - int(b[i]));
        }
        return sum / static_cast<double>(a.size());
    };

    const Camera start = poseAt(0.0, -0.6), end = poseAt(40.0, 0.6);
    // The converged picture at the final pose, from a fresh history.
    renderer.restartTemporalFilter();
    for (int frame = 0; frame < 32; ++frame) {
        renderer.render(end, settings);
    }
    const std::vector<std::uint8_t> converged = picture();

    renderer.restartTemporalFilter();
    for (int frame = 0; frame < 16; ++frame) {
        renderer.render(start, settings);
    }
    const std::vector<std::uint8_t> before = picture();
    // Five frames from one pose to the other: the silhouette jumps ~ 15 pixels a frame.
    for (int step = 1; step <= 5; ++step) {
        renderer.render(poseAt(8.0 * step, -0.6 + 0.24 * step), settings);
    }
    const double justArrived = meanDifference(picture(), converged);
    for (int frame = 0; frame < 8; ++frame) {
        renderer.render(end, settings);
    }
    const double settled = meanDifference(picture(), converged);
    const double poses = meanDifference(before, converged);
    EXPECT_GT(poses, 10.0) << "the two poses should look different";
    // The moving frames' clipping already removes most of the old pose...
    EXPECT_LT(justArrived, 0.1 * poses) << "before the stop: " << poses;
    // ...and 8 still frames leave 1/9 of what the motion left (~0.13 of a level here), plus
    // the difference between 8 and 32 jitter offsets at the silhouette (~0.2): within half a
    // level of 255 on average. Weighing the motion's history as all its frames leaves ~0.75.
    EXPECT_LT(settled, 0.5) << "just arrived: " << justArrived;
}

TEST(TemporalGLTest, OutlineCoverageBlendsTheColourOverTheBackground) {
    RenderSettings settings;
    settings.temporal.enabled = true;
    TemporalHarness harness(settings, kSpacing, TemporalDepth::SurfaceDepth);
    const Camera camera = harness.camera();
    // Column 1 lies on the outline, covered 0.6, the columns after it whole; column 0 is off
    // the mask, which decides the background whatever its alpha.
    Inputs inputs = planeInputs(
        camera, Plane{}, [](glm::dvec3, int, int) { return glm::vec3(0.8f); },
        [](int x, int) { return x == 0; });
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            inputs.coverage.push_back(x == 0 ? 0.25f : x == 1 ? 0.6f : 1.0f);
        }
    }
    const std::vector<float> history = harness.run(camera, inputs).first;
    const double background = srgbToLinear(settings.raster.backgroundSrgb.r);
    const std::size_t row = 4 * static_cast<std::size_t>(kHeight / 2 * kWidth);
    // Half floats: 2^-11 relative on values below 1. The history's alpha is the mask's.
    EXPECT_NEAR(history[row], background, 1e-3);
    EXPECT_NEAR(history[row + 3], 0.0, 1e-3);
    EXPECT_NEAR(history[row + 4], background + 0.6 * (0.8 - background), 1e-3);
    EXPECT_NEAR(history[row + 7], 1.0, 1e-3);
    EXPECT_NEAR(history[row + 8], 0.8, 1e-3);
}

}  // namespace
}  // namespace subscan
