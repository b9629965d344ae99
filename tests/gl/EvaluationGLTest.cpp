// The reconstruction's measured quality on the virtual scan of the sculpture (with scanner
// noise), against its analytic ground truth. Thresholds are the targets of the issue; 512x512
// keeps the ring and fins several pixels wide (at 256 the 1-pixel silhouette band alone is 4 %
// leakage) while the test stays within a few seconds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "eval/Evaluation.h"
#include "io/Image.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"
#include "support/QualityTargets.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

TEST(EvaluationGLTest, SculptureScanWithNoiseMeetsTheTargets) {
    const auto truth = makeBuiltInScene("sculpture");
    PointCloud points = makeSyntheticScene("sculpture");  // 200k points, 0.1 h noise
    points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 4;
    settings.width = 512;
    settings.height = 512;
    const EvaluationReport report =
        evaluate(test::glTestContext(), *truth, points, settings, RenderSettings{});
    test::expectQualityTargets(report);
}

/// The surface's metrics for `scene`'s points (40,000, 4 views at 256²) with the normals from
/// `normals` and, for the screen-space ones, the outline rule on or off.
QualityMetrics surfaceWithNormals(const std::string& scene, NormalSource normals,
                                  bool outlineNormals = true) {
    const auto truth = makeBuiltInScene(scene);
    PointCloud points = makeSyntheticScene(scene + "?points=40000");
    points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 4;
    settings.width = 256;
    settings.height = 256;
    RenderSettings render;
    render.surface.normals = normals;
    render.surface.outlineNormals = outlineNormals;
    return evaluate(test::glTestContext(), *truth, points, settings, render).surface;
}

// The points' own normals (estimated by PCA, carried through pull-push) against the paper's
// rebuilt from the filled depth, on a smooth surface and on one with creases and a hole. On
// llvmpipe (2026-12-06): the sphere 2.96 -> 0.43 degrees mean, 38.0 -> 40.7 dB; the box 7.53 ->
// 4.26 degrees, 27.3 -> 28.3 dB. The bounds keep about half of each gain, so a normal path that
// lost the points' normals anywhere (the resolve, the pull, the push, the blend) fails.
TEST(EvaluationGLTest, ThePointsNormalsBeatTheScreensOnCurvesAndCreases) {
    for (const std::string scene : {"sphere", "box-with-hole"}) {
        const QualityMetrics screen = surfaceWithNormals(scene, NormalSource::Screen);
        const QualityMetrics points = surfaceWithNormals(scene, NormalSource::Points);
        std::printf("%s: screen %.2f deg, %.2f dB; points %.2f deg, %.2f dB\n", scene.c_str(),
                    *screen.normalErrorMeanDeg, screen.psnrDb, *points.normalErrorMeanDeg,
                    points.psnrDb);
        const bool sphere = scene == "sphere";
        EXPECT_LT(*points.normalErrorMeanDeg, (sphere ? 0.3 : 0.75) * *screen.normalErrorMeanDeg)
            << scene;
        EXPECT_GT(points.psnrDb, screen.psnrDb + (sphere ? 1.3 : 0.5)) << scene;
        // The normals decide no pixel's coverage.
        EXPECT_EQ(points.coverage, screen.coverage) << scene;
    }
}

// Where a smooth surface turns away at its outline, its normal's component towards the eye
// falls to zero as the square root of the distance to it; smoothed normals stop a few pixels
// short of that, and a sphere's rim came out too bright under the head light. Against the
// sphere's exact normals, following the profile to the outline must win clearly; the box's
// outlines are creases between flat faces, with no such profile, and must not lose.
TEST(EvaluationGLTest, NormalsFollowARoundOutlineAndLeaveCreases) {
    const QualityMetrics sphereBefore = surfaceWithNormals("sphere", NormalSource::Screen, false);
    const QualityMetrics sphereAfter = surfaceWithNormals("sphere", NormalSource::Screen, true);
    std::printf("sphere: PSNR %.2f -> %.2f dB, normal error %.2f -> %.2f deg (p95 %.2f -> %.2f)\n",
                sphereBefore.psnrDb, sphereAfter.psnrDb, *sphereBefore.normalErrorMeanDeg,
                *sphereAfter.normalErrorMeanDeg, *sphereBefore.normalErrorP95Deg,
                *sphereAfter.normalErrorP95Deg);
    // Measured +2.9 dB and -0.3 degrees (llvmpipe, 2026-12-05); half of each leaves room for
    // another driver's rounding while a rule that turned too little or too much would fail.
    EXPECT_GT(sphereAfter.psnrDb, sphereBefore.psnrDb + 1.3);
    EXPECT_LT(*sphereAfter.normalErrorMeanDeg, *sphereBefore.normalErrorMeanDeg - 0.15);

    const QualityMetrics boxBefore =
        surfaceWithNormals("box-with-hole", NormalSource::Screen, false);
    const QualityMetrics boxAfter = surfaceWithNormals("box-with-hole", NormalSource::Screen, true);
    std::printf("box: PSNR %.2f -> %.2f dB, normal error %.2f -> %.2f deg\n", boxBefore.psnrDb,
                boxAfter.psnrDb, *boxBefore.normalErrorMeanDeg, *boxAfter.normalErrorMeanDeg);
    // Measured +0.2 dB (its hole's rim is round); the tolerances are the same runs' noise
    // between nearby settings, far below what the sphere gains.
    EXPECT_GT(boxAfter.psnrDb, boxBefore.psnrDb - 0.05);
    EXPECT_LT(*boxAfter.normalErrorMeanDeg, *boxBefore.normalErrorMeanDeg + 0.1);
}

// Points drawn at random have gaps several times their median spacing h wide (a randomly
// subsampled scan is drawn so). Seen through such a gap in the sphere's front, a point of its
// back lay beyond the hidden point test's radius, projected at that point's depth, of the front
// around the gap, and showed through. Measured on llvmpipe (2026-12-07), these 20,000 points:
// with the local spacing 1.0 % of the covered pixels before the walk went on to the nearer
// occluder's depth, 0.07 % after; with the global h alone 6.8 % before, 0.01 % after. The
// bound leaves room for another driver's rounding and fails at well under half the error
// before.
TEST(EvaluationGLTest, ARandomlySampledSphereHidesItsBack) {
    std::mt19937 random(7);
    std::normal_distribution<double> normal;
    std::vector<glm::dvec3> positions(20'000);
    for (glm::dvec3& position : positions) {
        position = glm::normalize(glm::dvec3(normal(random), normal(random), normal(random)));
    }
    PointCloud points = test::cloudOf(positions);
    points.colors.assign(points.size(), Rgba8{200, 200, 200, 255});
    EvaluationSettings settings;
    settings.views = 4;
    settings.width = 256;
    settings.height = 256;
    for (const bool localSpacing : {true, false}) {
        RenderSettings render;
        render.surface.localSpacing = localSpacing;
        const EvaluationReport report =
            evaluate(test::glTestContext(), *makeBuiltInScene("sphere"), points, settings, render);
        std::printf("local spacing %d: occlusion errors %.4f, coverage %.4f\n", localSpacing,
                    report.surface.occlusionErrorRate, report.surface.coverage);
        EXPECT_LT(report.surface.occlusionErrorRate, 0.004) << localSpacing;
        // Measured 0.996 both: hiding the back, not the front.
        EXPECT_GT(report.surface.coverage, 0.99) << localSpacing;
    }
}

/// The median distance from a point to its nearest other point, by brute force: the spacing h
/// of DESIGN.md §4 (the upper median, as estimateSpacing takes it), independently of its k-d tree.
double bruteForceSpacing(const PointCloud& cloud) {
    std::vector<double> nearest;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < cloud.size(); ++j) {
            const double d = glm::length(glm::dvec3(cloud.positions[i] - cloud.positions[j]));
            if (d > 0.0) {
                best = std::min(best, d);
            }
        }
        nearest.push_back(best);
    }
    const auto middle = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
    std::nth_element(nearest.begin(), middle, nearest.end());
    return *middle;
}

TEST(EvaluationGLTest, EvalCommandJsonHasTheDocumentedShape) {
    const auto result = test::runSubscan({"eval", "synthetic:sphere?points=3000", "--views", "1",
                                          "--width", "64", "--height", "64", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json json = nlohmann::json::parse(result.out);
    EXPECT_EQ(json["views"], 1);
    EXPECT_EQ(json["width"], 64);
    EXPECT_EQ(json["height"], 64);
    EXPECT_EQ(json["points"], 3000);
    EXPECT_EQ(json["surface_reduced_views"], 0);  // full resolution unless the settings say auto
    for (const char* method : {"points", "splats", "surface"}) {
        for (const char* key :
             {"coverage", "leakage", "depth_error_median_h", "depth_bias_h", "occlusion_error_rate",
              "normal_error_mean_deg", "normal_error_p95_deg", "psnr_db"}) {
            EXPECT_TRUE(json["methods"][method].contains(key)) << method << "." << key;
        }
    }
    EXPECT_TRUE(json["methods"]["points"]["normal_error_mean_deg"].is_null());
    EXPECT_TRUE(json["methods"]["surface"]["normal_error_mean_deg"].is_number());

    // The values. The unit sphere seen from the auto-framed distance d = 1.05 sqrt(3) /
    // sin(22.5°) = 4.75 has a silhouette of radius f / sqrt(d^2 - 1) = 16.6 pixels (f = 32 /
    // tan(22.5°) = 77.3): 872 pixels of truth (measured).
    const double focal = 32.0 / std::tan(glm::radians(22.5));
    const double distance = 1.05 * std::sqrt(3.0) / std::sin(glm::radians(22.5));
    const double radiusPixels = focal / std::sqrt(distance * distance - 1.0);
    // A reconstruction that keeps to the silhouette leaks at most the ring of pixels around it
    // whose centres miss the sphere, one pixel wide: 2 pi r / (pi r^2) = 2 / r = 0.120 of the
    // picture (measured 2026-12-03 on llvmpipe: points 0.063, surface 0.061; 2-pixel splats
    // reach a pixel further, 0.131).
    const double oneRing = 2.0 / radiusPixels;
    for (const char* method : {"points", "splats", "surface"}) {
        SCOPED_TRACE(method);
        const nlohmann::json& m = json["methods"][method];
        for (const char* share : {"coverage", "leakage", "occlusion_error_rate"}) {
            ASSERT_TRUE(m[share].is_number()) << share;
            EXPECT_GE(m[share].get<double>(), 0.0) << share;
            EXPECT_LE(m[share].get<double>(), 1.0) << share;
        }
        ASSERT_TRUE(m["depth_error_median_h"].is_number());
        ASSERT_TRUE(m["depth_bias_h"].is_number());
        const double median = m["depth_error_median_h"], bias = m["depth_bias_h"];
        EXPECT_TRUE(std::isfinite(median));
        EXPECT_GE(median, 0.0);
        // At least half the signed errors lie at or beyond the signed median, so at least half
        // the absolute ones do: |median(e)| <= median(|e|).
        EXPECT_LE(std::abs(bias), median);
        EXPECT_TRUE(std::isfinite(m["psnr_db"].get<double>()));
    }
    const nlohmann::json& points = json["methods"]["points"];
    const nlohmann::json& splats = json["methods"]["splats"];
    const nlohmann::json& surface = json["methods"]["surface"];
    EXPECT_LE(points["leakage"].get<double>(), oneRing);
    EXPECT_LE(surface["leakage"].get<double>(), oneRing);
    // The surface covers the whole disc (measured 1.0, all 872 pixels); 0.99 leaves 8 pixels
    // of the silhouette to another rasterizer's rounding, and fails a surface with a hole.
    EXPECT_GE(surface["coverage"].get<double>(), 0.99);
    // A splat of 2 pixels or more covers its point's own pixel: splats cover what points do.
    EXPECT_GE(splats["coverage"].get<double>(), points["coverage"].get<double>());
    EXPECT_GE(splats["point_size"].get<int>(), 2);  // EvaluationSettings' range of sizes
    EXPECT_LE(splats["point_size"].get<int>(), 8);
    // The points lie exactly on the sphere (the sphere's scan has no noise): their depth is
    // finite and errs only by where a point falls in its pixel (measured median 0.45 h).
    EXPECT_LT(points["depth_error_median_h"].get<double>(), 1.0);
    // The surface shades like the truth; 1-pixel points leave the background showing through
    // (measured 21.2 dB against 17.7 dB, splats 16.1 dB).
    EXPECT_GT(surface["psnr_db"].get<double>(), points["psnr_db"].get<double>());
    EXPECT_GT(surface["psnr_db"].get<double>(), splats["psnr_db"].get<double>());
    const double meanDeg = surface["normal_error_mean_deg"],
                 p95Deg = surface["normal_error_p95_deg"];
    for (const double degrees : {meanDeg, p95Deg}) {
        EXPECT_GE(degrees, 0.0);
        EXPECT_LE(degrees, 180.0);
    }

    // h is the scan's: the median nearest-neighbour distance of its 3000 points (float
    // positions: the two agree to ~1e-7, measured 0.0356331 both).
    const double spacing = json["spacing"];
    EXPECT_NEAR(spacing, bruteForceSpacing(makeSyntheticScene("sphere?points=3000")),
                1e-6 * spacing);
    // And it is what N points on the area A = 4 pi give: between the median of a Poisson
    // process, sqrt(ln 2 / pi) sqrt(A / N) = 0.47 sqrt(A / N) (fully irregular), and a
    // hexagonal packing's 1.075 sqrt(A / N) (fully regular). The scan's overlapping grids lie
    // in between (measured 0.551 sqrt(A / N) = 0.0356).
    const double perPoint = std::sqrt(4.0 * std::numbers::pi / 3000.0);
    EXPECT_GE(spacing, std::sqrt(std::log(2.0) / std::numbers::pi) * perPoint);
    EXPECT_LE(spacing, std::sqrt(2.0 / std::sqrt(3.0)) * perPoint);
}

TEST(EvaluationGLTest, TemporalEvaluationSeesMotionAndStillness) {
    // Not a sphere: turning about its centre, a sphere looks the same from every yaw.
    const auto truth = makeBuiltInScene("box-with-hole");
    PointCloud points = makeSyntheticScene("box-with-hole?points=20000");
    points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.width = 48;
    settings.height = 48;
    TemporalEvaluationSettings temporal;
    temporal.frames = 3;
    temporal.stillSamples = 8;
    // A camera that does not move: the truth and every unfiltered method repeat their
    // frames exactly, so no change is counted.
    temporal.stepDegrees = 0.0;
    const test::TempDir exported;
    settings.exportDirectory = exported.path();
    const TemporalReport still = evaluateTemporal(test::glTestContext(), *truth, points, settings,
                                                  temporal, RenderSettings{});
    // Every frame of every sequence is written, at the evaluation's size.
    for (int frame = 0; frame < temporal.frames; ++frame) {
        for (const char* name : {"truth", "points", "surface", "temporal", "supersampled"}) {
            const Image8 picture =
                readPng(exported / fmt::format("frame{:04}_{}.png", frame, name));
            EXPECT_EQ(picture.width, settings.width) << name;
            EXPECT_EQ(picture.height, settings.height) << name;
        }
    }
    settings.exportDirectory.clear();
    EXPECT_EQ(still.surface.temporalError, 0.0);
    EXPECT_EQ(still.surface.maskFlicker, 0.0);
    EXPECT_EQ(still.points1px.temporalError, 0.0);
    // The filter keeps averaging more offsets: its frames change, by under a level of 255.
    EXPECT_LT(still.surfaceTemporal.temporalError, 1.0 / 255.0);
    // Converged afresh at every pose over the same jitter pattern: the same picture each time.
    EXPECT_EQ(still.surfaceSupersampled.temporalError, 0.0);
    // Moving, the filter's sequence changes less against the truth's than the plain surface's
    // (measured on llvmpipe: E_t 0.0103 against 0.0114), and its first frame, converged, is
    // closer to the supersampled truth (22.93 dB against 22.66).
    settings.width = 64;
    settings.height = 64;
    temporal.frames = 6;
    temporal.stepDegrees = 2.0;
    const TemporalReport moving = evaluateTemporal(test::glTestContext(), *truth, points, settings,
                                                   temporal, RenderSettings{});
    EXPECT_LT(moving.surfaceTemporal.temporalError, moving.surface.temporalError);
    EXPECT_GT(moving.stillPsnrTemporalDb, moving.stillPsnrSurfaceDb);
    EXPECT_GT(moving.surface.psnrDb, 15.0) << "the box should be recognisable";
    // Anti-aliased at every pose, without the moving filter's lag: closer to the supersampled
    // truth frame by frame and steadier than the plain surface (measured on llvmpipe: PSNR
    // 23.07 against 22.93 dB, E_t 0.0090 against 0.0114).
    EXPECT_GT(moving.surfaceSupersampled.psnrDb, moving.surface.psnrDb);
    EXPECT_LT(moving.surfaceSupersampled.temporalError, moving.surface.temporalError);

    const nlohmann::json json = toJson(moving);
    for (const char* method :
         {"points", "splats", "surface", "surface_temporal", "surface_supersampled"}) {
        for (const char* key : {"temporal_error", "mask_flicker", "psnr_db"}) {
            EXPECT_TRUE(json["methods"][method].contains(key)) << method << "." << key;
        }
    }
    EXPECT_TRUE(json["methods"]["surface_temporal"].contains("still_psnr_db"));
}

TEST(EvaluationGLTest, EvalReconstructsAScanFileAgainstTheMesh) {
    const test::TempDir dir;
    const auto mesh = dir.write("mesh.ply",
                                "ply\nformat ascii 1.0\nelement vertex 4\n"
                                "property float x\nproperty float y\nproperty float z\n"
                                "element face 2\nproperty list uchar int vertex_indices\n"
                                "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    std::string scan;
    for (int i = 0; i < 20; ++i) {
        for (int j = 0; j < 20; ++j) {
            scan += std::to_string(0.05 * i) + " " + std::to_string(0.05 * j) + " 0\n";
        }
    }
    const auto scanFile = dir.write("scan.xyz", scan);
    const auto result =
        test::runSubscan({"eval", mesh.string(), "--points", scanFile.string(), "--views", "1",
                          "--width", "32", "--height", "32", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_EQ(nlohmann::json::parse(result.out)["points"], 400);  // the file's, not the mesh's 4
}

TEST(EvaluationGLTest, EvalRefusesAPointCloudWithoutFaces) {
    const test::TempDir dir;
    const auto cloud = dir.write("cloud.xyz", "0 0 0\n1 0 0\n0 1 0\n");
    const auto result = test::runSubscan({"eval", cloud.string()});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, ::testing::HasSubstr("has no faces"));
}

}  // namespace
}  // namespace subscan
