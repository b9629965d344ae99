// The reconstruction's measured quality on the virtual scan of the sculpture (with scanner
// noise), against its analytic ground truth. Thresholds are the targets of the issue; 512x512
// keeps the ring and fins several pixels wide (at 256 the 1-pixel silhouette band alone is 4 %
// leakage) while the test stays within a few seconds.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "eval/Evaluation.h"
#include "scan/SyntheticScenes.h"
#include "support/GlTestSupport.h"
#include "support/QualityTargets.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

TEST(EvaluationGLTest, SculptureScanWithNoiseMeetsTheTargets) {
    const auto truth = makeBuiltInScene("sculpture");
    const PointCloud points = makeSyntheticScene("sculpture");  // 200k points, 0.1 h noise
    EvaluationSettings settings;
    settings.views = 4;
    settings.width = 512;
    settings.height = 512;
    const EvaluationReport report =
        evaluate(test::glTestContext(), *truth, points, settings, RenderSettings{});
    test::expectQualityTargets(report);
}

TEST(EvaluationGLTest, EvalCommandJsonHasTheDocumentedShape) {
    const auto result = test::runSubscan({"eval", "synthetic:sphere?points=3000", "--views", "1",
                                          "--width", "64", "--height", "64", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json json = nlohmann::json::parse(result.out);
    EXPECT_EQ(json["views"], 1);
    EXPECT_EQ(json["width"], 64);
    EXPECT_EQ(json["points"], 3000);
    for (const char* method : {"points", "splats", "surface"}) {
        for (const char* key :
             {"coverage", "leakage", "depth_error_median_h", "depth_bias_h", "occlusion_error_rate",
              "normal_error_mean_deg", "normal_error_p95_deg", "psnr_db"}) {
            EXPECT_TRUE(json["methods"][method].contains(key)) << method << "." << key;
        }
    }
    EXPECT_TRUE(json["methods"]["points"]["normal_error_mean_deg"].is_null());
    EXPECT_TRUE(json["methods"]["surface"]["normal_error_mean_deg"].is_number());
}

TEST(EvaluationGLTest, TemporalEvaluationSeesMotionAndStillness) {
    // Not a sphere: turning about its centre, a sphere looks the same from every yaw.
    const auto truth = makeBuiltInScene("box-with-hole");
    const PointCloud points = makeSyntheticScene("box-with-hole?points=20000");
    EvaluationSettings settings;
    settings.width = 48;
    settings.height = 48;
    TemporalEvaluationSettings temporal;
    temporal.frames = 3;
    temporal.stillSamples = 8;
    // A camera that does not move: the truth and every unfiltered method repeat their
    // frames exactly, so no change is counted.
    temporal.stepDegrees = 0.0;
    const TemporalReport still = evaluateTemporal(test::glTestContext(), *truth, points, settings,
                                                  temporal, RenderSettings{});
    EXPECT_EQ(still.surface.temporalError, 0.0);
    EXPECT_EQ(still.surface.maskFlicker, 0.0);
    EXPECT_EQ(still.points1px.temporalError, 0.0);
    // The filter keeps averaging more offsets: its frames change, by under a level of 255.
    EXPECT_LT(still.surfaceTemporal.temporalError, 1.0 / 255.0);
    // Moving, the filter's sequence changes less against the truth's than the plain surface's
    // (measured on llvmpipe: E_t 0.0113 against 0.0125), and its first frame, converged, is
    // closer to the supersampled truth (21.36 dB against 21.26).
    settings.width = 64;
    settings.height = 64;
    temporal.frames = 6;
    temporal.stepDegrees = 2.0;
    const TemporalReport moving = evaluateTemporal(test::glTestContext(), *truth, points, settings,
                                                   temporal, RenderSettings{});
    EXPECT_LT(moving.surfaceTemporal.temporalError, moving.surface.temporalError);
    EXPECT_GT(moving.stillPsnrTemporalDb, moving.stillPsnrSurfaceDb);
    EXPECT_GT(moving.surface.psnrDb, 15.0) << "the box should be recognisable";

    const nlohmann::json json = toJson(moving);
    for (const char* method : {"points", "splats", "surface", "surface_temporal"}) {
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
