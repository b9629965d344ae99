// The evaluation of LiDAR sources (a station, an airborne strip) at a small size: its views
// near the scanner, coverage counted over the surfaces the scan sampled.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>

#include "core/Camera.h"
#include "core/LocalSpacing.h"
#include "eval/Evaluation.h"
#include "eval/GroundTruth.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

void expectFraction(double value, const char* what) {
    EXPECT_GE(value, 0.0) << what;
    EXPECT_LE(value, 1.0) << what;
}

/// Of a view's true surface pixels, how many there are and how many of them the scan could not
/// sample.
struct SampledCount {
    std::size_t surface = 0, unsampled = 0;
};
SampledCount countSampled(const GroundTruthImages& truth) {
    SampledCount count;
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        if (std::isfinite(truth.depth[i])) {
            ++count.surface;
            count.unsampled += truth.sampled[i] == 0;
        }
    }
    return count;
}

/// `views` square views of `size` pixels near the source's scanner.
EvaluationSettings viewsNearTheScanner(const SyntheticSource& source, int views, int size) {
    EvaluationSettings settings;
    settings.views = views;
    settings.width = size;
    settings.height = size;
    adaptToScanner(settings, *source.scene, source.scanner);
    return settings;
}

TEST(LidarEvaluationGLTest, StationSourceGivesMetricsFromViewsNearTheStation) {
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=30000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    const EvaluationSettings settings = viewsNearTheScanner(source, 2, 96);
    ASSERT_EQ(settings.viewpoints.size(), 2u);
    // Each view's eye stands within 1.5 m of the station (1 m up, 1 m back).
    for (const OrbitView& view : settings.viewpoints) {
        const Camera camera = orbitCamera(source.scene->bounds(), view, 96, 96, 45.0);
        EXPECT_LT(glm::length(camera.eye() - *source.scanner.station.position), 1.5);
    }
    const EvaluationReport report =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, RenderSettings{});
    EXPECT_EQ(report.views, 2);
    for (const QualityMetrics& m : {report.points1px, report.surface}) {
        expectFraction(m.coverage, "coverage");
        expectFraction(m.leakage, "leakage");
        expectFraction(m.occlusionErrorRate, "occlusion errors");
    }
    // The surface fills between the points: it must cover far more than 1-pixel points do,
    // and at least half of what the station saw even at this size (typically over 0.8).
    EXPECT_GT(report.surface.coverage, report.points1px.coverage);
    EXPECT_GT(report.surface.coverage, 0.5);
}

TEST(LidarEvaluationGLTest, AStreamedSurfaceIsTheWholeCloudsAtAFullBudget) {
    // eval --point-budget: the points indexed into a COPC file, each view loading its nodes.
    // More points than one node holds (100,000), so that a budget can leave some out.
    SyntheticSource source = makeSyntheticSource("outdoor-airborne?points=250000");
    source.points.normals.clear();
    EvaluationSettings settings = viewsNearTheScanner(source, 2, 128);
    RenderSettings render;
    render.surface.normals = NormalSource::Screen;  // what a streamed view uses under auto
    const EvaluationReport whole =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, render);
    settings.pointBudget = source.points.size();
    const EvaluationReport all =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, render);
    EXPECT_DOUBLE_EQ(all.surfacePoints, static_cast<double>(source.points.size()));
    // The same points, quantized to the COPC file's grid (well below a millimetre here) and in
    // another order: the metrics agree to a few pixels of 16,384 a view.
    EXPECT_NEAR(all.surface.coverage, whole.surface.coverage, 0.002);
    EXPECT_NEAR(all.surface.leakage, whole.surface.leakage, 0.002);
    EXPECT_NEAR(all.surface.occlusionErrorRate, whole.surface.occlusionErrorRate, 0.002);
    EXPECT_NEAR(all.surface.psnrDb, whole.surface.psnrDb, 0.2);

    // A small budget: the views load part of the points and still show a surface.
    settings.pointBudget = 100'000;
    const EvaluationReport part =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, render);
    EXPECT_LE(part.surfacePoints, 100'000.0);
    EXPECT_GT(part.surfacePoints, 10'000.0);
    EXPECT_GT(part.surface.coverage, 0.8);
    EXPECT_LT(part.surface.coverage, all.surface.coverage + 0.01);
}

TEST(LidarEvaluationGLTest, AStreamedOrbitDrawsOneSetOfNodesAndStaysAsSteady) {
    // eval --temporal --point-budget: one set of nodes for the whole orbit (those any frame
    // selects), as the viewer keeps its nodes while the camera moves.
    SyntheticSource source = makeSyntheticSource("outdoor-airborne?points=250000");
    source.points.normals.clear();
    EvaluationSettings settings;
    settings.width = 96;
    settings.height = 96;
    TemporalEvaluationSettings temporal;
    temporal.frames = 4;
    temporal.stepDegrees = 2.0;
    temporal.stillSamples = 4;
    temporal.supersampling = 2;
    RenderSettings render;
    render.surface.normals = NormalSource::Screen;  // what a streamed view uses under auto
    const TemporalReport whole = evaluateTemporal(test::glTestContext(), *source.scene,
                                                  source.points, settings, temporal, render);
    EXPECT_EQ(whole.surfacePoints, source.points.size());
    // The nodes any frame needs: at 96x96 the deepest level adds no detail to most of them.
    settings.pointBudget = source.points.size();
    const TemporalReport needed = evaluateTemporal(test::glTestContext(), *source.scene,
                                                   source.points, settings, temporal, render);
    EXPECT_LT(needed.surfacePoints, source.points.size());
    EXPECT_GT(needed.surfacePoints, source.points.size() / 2);
    // The baselines draw every point either way.
    EXPECT_EQ(needed.points1px.temporalError, whole.points1px.temporalError);
    // Nearly every point a frame draws, at another order and the COPC file's grid: the
    // sequences change alike (measured: E_t 0.00697 against 0.00694, PSNR 27.01 against 27.02).
    EXPECT_NEAR(needed.surface.temporalError, whole.surface.temporalError,
                0.05 * whole.surface.temporalError);
    EXPECT_NEAR(needed.surface.psnrDb, whole.surface.psnrDb, 0.2);

    settings.pointBudget = 50'000;
    const TemporalReport part = evaluateTemporal(test::glTestContext(), *source.scene,
                                                 source.points, settings, temporal, render);
    EXPECT_LE(part.surfacePoints, 50'000u);
    EXPECT_GT(part.surfacePoints, 10'000u);
    // One set for every frame: nothing arrives or leaves along the orbit, so the streamed
    // surface changes about as the whole one does (issue 43's bound: 1.2 times; measured
    // with 18,751 points: 1.07 times unfiltered, 1.04 times through the temporal filter).
    EXPECT_LT(part.surface.temporalError, 1.2 * whole.surface.temporalError);
    EXPECT_LT(part.surfaceTemporal.temporalError, 1.2 * whole.surfaceTemporal.temporalError);
}

TEST(LidarEvaluationGLTest, LocalSpacingFillsTheStationsSparseFarField) {
    // At 320 px the far ground's rings of 50,000 points lie several pixels apart: the global h
    // (the spacing near the station) leaves them apart, the local spacing closes them. (With
    // 100,000 points the gap test, which looks up to 2 texels beyond the pixel, closes most of
    // them with h alone since 2026-12-06: coverage 0.945.)
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=50000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    const EvaluationSettings settings = viewsNearTheScanner(source, 2, 320);
    RenderSettings local;
    RenderSettings global;
    global.surface.localSpacing = false;
    const EvaluationReport withLocal =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, local);
    const EvaluationReport withGlobal =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, global);
    // docs/eval.md's targets (coverage >= 0.97, leakage <= 0.03, occlusion errors <= 0.01) with a
    // margin for two small views instead of four at 1024 px (measured 2026-12-06: 0.995,
    // 0.006, 0.0004 against the global h's 0.780, 0.000, 0.0002).
    EXPECT_GE(withLocal.surface.coverage, 0.96);
    EXPECT_LE(withLocal.surface.leakage, 0.03);
    EXPECT_LE(withLocal.surface.occlusionErrorRate, 0.015);
    EXPECT_GT(withLocal.surface.coverage, withGlobal.surface.coverage + 0.1);
    EXPECT_GT(withLocal.surface.psnrDb, withGlobal.surface.psnrDb + 3.0);  // measured +9.7 dB
}

TEST(LidarEvaluationGLTest, OrbitViewsLookDownAtTheWholeStationScene) {
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=30000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 4;
    adaptToScanner(settings, *source.scene, source.scanner, ViewsFrom::Orbit);
    ASSERT_EQ(settings.viewpoints.size(), 4u);
    const Bounds bounds = source.scene->bounds();
    const glm::dvec3 centre = bounds.center();
    for (const OrbitView& view : settings.viewpoints) {
        const Camera camera = orbitCamera(bounds, view, 96, 96, 45.0);
        // Outside the scene, 30 degrees above its middle, looking at it: the station's
        // sparse far walls stand between these eyes and its dense near ground.
        const glm::dvec3 eye = camera.eye();
        EXPECT_FALSE(eye.x > bounds.min.x && eye.x < bounds.max.x && eye.z > bounds.min.z &&
                     eye.z < bounds.max.z);
        const glm::dvec3 towardsEye = glm::normalize(eye - centre);
        EXPECT_NEAR(std::asin(towardsEye.y), glm::radians(30.0), 1e-6);
    }
    // The scan's own sampling still decides what counts: the truth leaves unsampled surfaces
    // (backs of buildings, ground behind walls) out, which the orbit sees plenty of.
    const Camera camera = orbitCamera(bounds, settings.viewpoints[0], 96, 96, 45.0);
    const SampledCount count =
        countSampled(renderGroundTruth(*source.scene, camera, settings.sampled));
    ASSERT_GT(count.surface, 0u);
    EXPECT_GT(count.unsampled, 0u);
    EXPECT_LT(count.unsampled, count.surface);
}

TEST(LidarEvaluationGLTest, FromTheOrbitTheFillKeepsNearTheStationsPoints) {
    // Seen from above, the station's far ground is a few sparse rings: the fill must stay
    // within them, not run on past the outermost in blocks of coarse pyramid texels.
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=100000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 2;
    settings.width = 320;
    settings.height = 320;
    adaptToScanner(settings, *source.scene, source.scanner, ViewsFrom::Orbit);
    const EvaluationReport report =
        evaluate(test::glTestContext(), *source.scene, source.points, settings, RenderSettings{});
    // Measured 2026-12-06: coverage 0.948, leakage 0.047. The reach beyond the outermost
    // points in every direction (the rule before the rings' axis) gave 0.980 and 0.071 once
    // the passes' region took the reach in, and 0.978 and 0.054 while the region cut it; the
    // fill in blocks (the pull weight as the gap test's evidence) 0.966 and 0.095. The
    // leakage left is the reach across the outermost ring where the ground ends sooner; the
    // coverage given up, at this low resolution, the ground between a ring's end and an edge
    // the rings cross obliquely (docs/eval.md).
    EXPECT_GE(report.surface.coverage, 0.93);
    EXPECT_LE(report.surface.leakage, 0.06);
}

TEST(LidarEvaluationGLTest, OcclusionsAreJudgedByTheStationsSpacingWhereTheTruthIs) {
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=30000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 1;
    adaptToScanner(settings, *source.scene, source.scanner, ViewsFrom::Orbit);
    EXPECT_TRUE(settings.occlusionsByLocalSpacing);
    const PointSpacing spacing = estimatePointSpacing(source.points);
    ASSERT_FALSE(spacing.local.empty());
    const Camera camera =
        orbitCamera(source.scene->bounds(), settings.viewpoints[0], 128, 128, 45.0);
    const GroundTruthImages truth = renderGroundTruth(*source.scene, camera, settings.sampled);
    const std::vector<float> atTruth = SpacingAtTruth(source.points, spacing).at(camera, truth);
    ASSERT_EQ(atTruth.size(), truth.depth.size());
    // A station's points lie farther apart with range: on the sampled surfaces near the
    // station (within 5 m) the spacing is a few h, beyond 20 m many times that (the rings).
    const glm::dmat4 worldFromView = glm::inverse(camera.view);
    std::vector<double> nearRatios, farRatios;
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        if (!std::isfinite(truth.depth[i]) || truth.sampled[i] == 0) {
            continue;
        }
        const glm::dvec3 inView =
            static_cast<double>(truth.depth[i]) *
            pixelCentreDirection(camera, static_cast<int>(i % 128), static_cast<int>(i / 128));
        const glm::dvec3 world(worldFromView * glm::dvec4(inView, 1.0));
        const glm::dvec3 offset = world - *source.scanner.station.position;
        const double range = std::hypot(offset.x, offset.z);
        const double ratio = atTruth[i] / spacing.global;
        if (range < 5.0) {
            nearRatios.push_back(ratio);
        } else if (range > 20.0) {
            farRatios.push_back(ratio);
        }
    }
    ASSERT_GT(nearRatios.size(), 10u);
    ASSERT_GT(farRatios.size(), 100u);
    const auto median = [](std::vector<double> values) {
        std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
        return values[values.size() / 2];
    };
    // Measured: 3.3 h near, 130 h far (the far rings' gaps; 30,000 points).
    EXPECT_LT(median(nearRatios), 6.0);
    EXPECT_GT(median(farRatios), 10.0 * median(nearRatios));
}

TEST(LidarEvaluationGLTest, AirborneTruthLeavesWallsAlongTheTrackUnsampled) {
    SyntheticSource source = makeSyntheticSource("outdoor-airborne?points=2000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings;
    settings.views = 4;
    adaptToScanner(settings, *source.scene, source.scanner);
    ASSERT_EQ(settings.viewpoints.size(), 4u);
    // Looking down at 45 degrees from +X+Z, the walls facing +X (parallel to the scan planes)
    // are in view: unsampled, while the ground and the roofs are sampled.
    const Camera camera = orbitCamera(source.scene->bounds(), settings.viewpoints[0], 96, 96, 45.0);
    const GroundTruthImages truth = renderGroundTruth(*source.scene, camera, settings.sampled);
    ASSERT_EQ(truth.sampled.size(), truth.depth.size());
    const SampledCount count = countSampled(truth);
    ASSERT_GT(count.surface, 0u);
    const double share = static_cast<double>(count.unsampled) / static_cast<double>(count.surface);
    // The office's and the tower's +X walls cover a few percent of the view; everything else is
    // sampled, so the share is small but not zero.
    EXPECT_GT(share, 0.002);
    EXPECT_LT(share, 0.2);
}

TEST(LidarEvaluationGLTest, TemporalEvaluationFollowsTheScannersPath) {
    SyntheticSource source = makeSyntheticSource("outdoor-station?points=30000");
    source.points.normals.clear();  // the scanner's true ones: eval estimates its own
    EvaluationSettings settings = viewsNearTheScanner(source, 4, 48);
    const Bounds bounds = source.scene->bounds();
    auto eyeOf = [&](const OrbitView& view) {
        return orbitCamera(bounds, view, 48, 48, 45.0).eye();
    };
    // The path turns at the station: every turn keeps the eye within 1.5 m of it (1 m up, 1 m
    // back).
    for (const double degrees : {0.0, 7.0, 200.0}) {
        EXPECT_LT(
            glm::length(eyeOf(settings.scannerView(degrees)) - *source.scanner.station.position),
            1.5)
            << degrees;
    }

    // evaluateTemporal takes its cameras from the path: one that looks straight up from above
    // the scene sees only sky, which every method shows exactly as the truth does (the orbit
    // around the scene would not).
    settings.scannerView = [&bounds](double degrees) {
        OrbitView upwards;
        upwards.center = glm::dvec3(bounds.center().x, bounds.max.y + 100.0, bounds.center().z);
        upwards.distance = 50.0;
        upwards.pitchDegrees = -89.0;
        upwards.yawDegrees = degrees;
        return upwards;
    };
    TemporalEvaluationSettings temporal;
    temporal.frames = 3;
    temporal.stillSamples = 2;
    temporal.stepDegrees = 5.0;
    const TemporalReport sky = evaluateTemporal(test::glTestContext(), *source.scene, source.points,
                                                settings, temporal, RenderSettings{});
    for (const TemporalMetrics& m :
         {sky.points1px, sky.splats, sky.surface, sky.surfaceTemporal, sky.surfaceSupersampled}) {
        EXPECT_EQ(m.temporalError, 0.0);
        EXPECT_EQ(m.psnrDb, 100.0);  // psnr()'s value for identical pictures
    }
}

}  // namespace
}  // namespace subscan
