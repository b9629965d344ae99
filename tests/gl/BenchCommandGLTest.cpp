// `subscan bench` on llvmpipe: a smoke test of its JSON with few frames at a small size.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;

TEST(BenchCommandGLTest, ReportsEveryModeAsJson) {
    const auto result = runSubscan({"bench", "synthetic:sphere?points=4000", "--frames", "12",
                                    "--warmup", "1", "--width", "64", "--height", "48", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json report = nlohmann::json::parse(result.out);
    EXPECT_FALSE(report["renderer"].get<std::string>().empty());
    EXPECT_EQ(report["points"], 4000);
    EXPECT_EQ(report["width"], 64);
    EXPECT_EQ(report["height"], 48);
    ASSERT_EQ(report["modes"].size(), 4u);
    for (const char* mode : {"points-gl", "points", "surface", "sss"}) {
        SCOPED_TRACE(mode);
        const nlohmann::json& m = report["modes"][mode];
        const double average = m["avg_fps"], low = m["low1_fps"];
        EXPECT_GT(average, 0.0);
        EXPECT_GT(low, 0.0);
        EXPECT_LE(low, average * 1.0000001);  // the slowest 1 % is never faster than the mean
        EXPECT_GT(m["frame_ms_median"].get<double>(), 0.0);
        EXPECT_NEAR(m["points_per_second"].get<double>(), average * 4000, 1e-6 * average * 4000);
        EXPECT_GT(m["gpu_memory_mb"].get<double>(), 0.0);
        // The last pass makes the picture: the surface mode finishes it in one dispatch.
        EXPECT_TRUE(m["per_pass_ms"].contains(std::string(mode) == "surface" ? "FinishSurface"
                                                                             : "Present"));
    }
    EXPECT_TRUE(report["modes"]["surface"]["per_pass_ms"].contains("PullPush"));
    EXPECT_TRUE(report["modes"]["sss"]["per_pass_ms"].contains("SubsurfaceScattering"));
    // The surface pipeline holds more than the points' buffers.
    EXPECT_GT(report["modes"]["surface"]["gpu_memory_mb"].get<double>(),
              report["modes"]["points"]["gpu_memory_mb"].get<double>());
}

TEST(BenchCommandGLTest, CountsTheFramesReconstructedAtHalfResolution) {
    const auto result = runSubscan({"bench", "synthetic:sphere?points=4000", "--frames", "6",
                                    "--warmup", "0", "--width", "64", "--height", "48", "--modes",
                                    "points,surface", "--resolution", "half", "--json"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json report = nlohmann::json::parse(result.out);
    EXPECT_EQ(report["resolution"], "half");
    EXPECT_EQ(report["modes"]["surface"]["reduced_resolution_frames"], 6);
    EXPECT_EQ(report["modes"]["points"]["reduced_resolution_frames"], 0);  // points: every pixel
}

TEST(BenchCommandGLTest, UnknownModeIsOneSentence) {
    const auto result =
        runSubscan({"bench", "synthetic:sphere", "--frames", "2", "--modes", "surface,voxels"});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_THAT(result.err, ::testing::HasSubstr("'voxels' is not a render mode"));
}

}  // namespace
}  // namespace subscan
