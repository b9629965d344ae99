#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "eval/Metrics.h"

namespace subscan {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

TEST(MetricsTest, CountsCoverageLeakageDepthAndOcclusion) {
    // 10 pixels: truth covers 0..7; the reconstruction covers 2..9.
    GroundTruthImages truth{10, 1, std::vector<float>(10, kInf),
                            std::vector<glm::vec3>(10, {0, 0, 1}), std::vector<glm::vec3>(10)};
    ReconstructionImages reconstruction{std::vector<float>(10, kInf), {}};
    for (int i = 0; i < 8; ++i) {
        truth.depth[i] = 1.0f;
    }
    const float h = 0.01f;
    // rec ∩ truth = 2..7 (6 pixels): errors in h of 0, 1, 2, 3.5, 4, 10 (the last three behind).
    const float errors[6] = {0, 1, 2, 3.5f, 4, 10};
    for (int i = 2; i < 8; ++i) {
        reconstruction.depth[i] = 1.0f + errors[i - 2] * h;
    }
    reconstruction.depth[8] = reconstruction.depth[9] = 2.0f;
    const QualityMetrics m = compareToGroundTruth(reconstruction, truth, h);
    EXPECT_DOUBLE_EQ(m.coverage, 6.0 / 8.0);
    EXPECT_DOUBLE_EQ(m.leakage, 2.0 / 8.0);
    // Median of 6 values (0 1 2 3.5 4 10): the element at index round(2.5) = 3 after sorting.
    // Float depths make the errors inexact by ~1e-5 h.
    EXPECT_NEAR(m.depthErrorMedianH, 3.5, 1e-3);
    EXPECT_NEAR(m.depthBiasH, 3.5, 1e-3);               // all behind: the signed median is the same
    EXPECT_DOUBLE_EQ(m.occlusionErrorRate, 3.0 / 6.0);  // 3.5, 4 and 10 exceed 3 h
    EXPECT_FALSE(m.normalErrorMeanDeg.has_value());     // no normals given
}

TEST(MetricsTest, OcclusionsScaleWithTheScansSpacingWhereGiven) {
    // 4 pixels, each reconstructed 10 h behind the truth; the scan's spacing there is 0 (none
    // known: h stands), 2 h, 3.5 h and 5 h. Behind by more than 3 times the larger of h and
    // that spacing: the first two (10 h > 3 h, 6 h), not the last two (10.5 h, 15 h).
    const float h = 0.01f;
    GroundTruthImages truth{4, 1, std::vector<float>(4, 1.0f), std::vector<glm::vec3>(4, {0, 0, 1}),
                            std::vector<glm::vec3>(4)};
    truth.spacing = {0.0f, 2 * h, 3.5f * h, 5 * h};
    const ReconstructionImages reconstruction{std::vector<float>(4, 1.0f + 10 * h), {}};
    EXPECT_DOUBLE_EQ(compareToGroundTruth(reconstruction, truth, h).occlusionErrorRate, 0.5);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(showsThrough(truth, i, reconstruction.depth[i], h), i < 2) << i;
    }
    // Without the spacing, h alone: all four.
    truth.spacing.clear();
    EXPECT_DOUBLE_EQ(compareToGroundTruth(reconstruction, truth, h).occlusionErrorRate, 1.0);
}

TEST(MetricsTest, OcclusionsLeaveTheDepthsTheTrueSurfaceTakesWithinThePixel) {
    // 3 pixels, each reconstructed 4 h behind the truth (more than 3 h); within them the true
    // surface reaches 0, 0.5 h and 1.5 h from the centre's depth. Only the last takes the
    // reconstruction in (4 h < 3 h + 1.5 h).
    const float h = 0.01f;
    GroundTruthImages truth{3, 1, std::vector<float>(3, 1.0f), std::vector<glm::vec3>(3, {0, 0, 1}),
                            std::vector<glm::vec3>(3)};
    truth.depthWithinPixel = {0.0f, 0.5f * h, 1.5f * h};
    const ReconstructionImages reconstruction{std::vector<float>(3, 1.0f + 4 * h), {}};
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(showsThrough(truth, i, reconstruction.depth[i], h), i < 2) << i;
    }
    EXPECT_DOUBLE_EQ(compareToGroundTruth(reconstruction, truth, h).occlusionErrorRate, 2.0 / 3.0);
}

TEST(MetricsTest, UnsampledTruthCountsNeitherForCoverageNorForLeakage) {
    // 8 pixels of truth, 0..7; the scan could sample only 0..3. The reconstruction covers 0..2
    // and 4..5 (true surface it could not know about) and 9 (nothing there).
    GroundTruthImages truth{10,
                            1,
                            std::vector<float>(10, kInf),
                            std::vector<glm::vec3>(10, {0, 0, 1}),
                            std::vector<glm::vec3>(10),
                            std::vector<std::uint8_t>(10, 0)};
    ReconstructionImages reconstruction{std::vector<float>(10, kInf), {}};
    for (int i = 0; i < 8; ++i) {
        truth.depth[i] = 1.0f;
        truth.sampled[i] = i < 4;
    }
    for (const int i : {0, 1, 2, 4, 5, 9}) {
        reconstruction.depth[i] = 1.0f;
    }
    const QualityMetrics m = compareToGroundTruth(reconstruction, truth, 0.01);
    EXPECT_DOUBLE_EQ(m.coverage, 3.0 / 4.0);  // 3 of the 4 sampled true pixels
    EXPECT_DOUBLE_EQ(m.leakage, 1.0 / 4.0);   // pixel 9 of the 4 judged reconstructed pixels
    truth.sampled.clear();                    // every true pixel counts again
    const QualityMetrics all = compareToGroundTruth(reconstruction, truth, 0.01);
    EXPECT_DOUBLE_EQ(all.coverage, 5.0 / 8.0);
    EXPECT_DOUBLE_EQ(all.leakage, 1.0 / 6.0);
}

TEST(MetricsTest, DepthBiasIsTheSignedMedianInFrontOfTheTruthNegative) {
    GroundTruthImages truth{5, 1, std::vector<float>(5, 2.0f), std::vector<glm::vec3>(5, {0, 0, 1}),
                            std::vector<glm::vec3>(5)};
    const float h = 0.01f;
    // Errors in h of -3, -2, -1, 0.5, 4: sorted, the middle is -1; unsigned, 2.
    ReconstructionImages reconstruction{
        {2.0f - 3 * h, 2.0f - 2 * h, 2.0f - h, 2.0f + 0.5f * h, 2.0f + 4 * h}, {}};
    const QualityMetrics m = compareToGroundTruth(reconstruction, truth, h);
    // Float depths around 2 carry ~2e-7 / h = 2e-5 h of rounding.
    EXPECT_NEAR(m.depthBiasH, -1.0, 1e-3);
    EXPECT_NEAR(m.depthErrorMedianH, 2.0, 1e-3);
    EXPECT_DOUBLE_EQ(m.occlusionErrorRate, 1.0 / 5.0);  // only the 4 h behind counts
}

TEST(MetricsTest, NormalErrorsInDegrees) {
    GroundTruthImages truth{4, 1, std::vector<float>(4, 1.0f), std::vector<glm::vec3>(4, {0, 0, 1}),
                            std::vector<glm::vec3>(4)};
    ReconstructionImages reconstruction{std::vector<float>(4, 1.0f), {}};
    for (const double degrees : {0.0, 10.0, 20.0, 90.0}) {
        const double radians = glm::radians(degrees);
        // Unnormalised on purpose: the metric normalises the reconstruction.
        reconstruction.normals.push_back(
            glm::vec3(2.0 * std::sin(radians), 0.0, 2.0 * std::cos(radians)));
    }
    const QualityMetrics m = compareToGroundTruth(reconstruction, truth, 1.0);
    // float normals: angles are exact to ~1e-5 degrees.
    EXPECT_NEAR(*m.normalErrorMeanDeg, 30.0, 1e-3);
    EXPECT_NEAR(*m.normalErrorP95Deg, 90.0, 1e-3);  // index round(0.95 * 3) = 3: the largest
}

TEST(MetricsTest, PsnrOfKnownDifferences) {
    const std::vector<std::uint8_t> a(400, 100);
    std::vector<std::uint8_t> b = a;
    EXPECT_EQ(psnr(a, b), 100.0);  // identical: capped
    for (std::size_t i = 0; i < b.size(); i += 4) {
        b[i] = 110;    // red off by 10 everywhere: MSE over RGB = 100 / 3
        b[i + 3] = 0;  // alpha ignored
    }
    EXPECT_NEAR(psnr(a, b), 10.0 * std::log10(255.0 * 255.0 / (100.0 / 3.0)), 1e-9);
}

TEST(MetricsTest, AverageOverViews) {
    QualityMetrics a, b;
    a.coverage = 0.9;
    b.coverage = 1.0;
    a.normalErrorMeanDeg = 4.0;
    a.normalErrorP95Deg = 8.0;
    b.normalErrorMeanDeg = 6.0;
    b.normalErrorP95Deg = 10.0;
    const QualityMetrics mean = average({a, b});
    EXPECT_DOUBLE_EQ(mean.coverage, 0.95);
    EXPECT_DOUBLE_EQ(*mean.normalErrorMeanDeg, 5.0);
    EXPECT_DOUBLE_EQ(*mean.normalErrorP95Deg, 9.0);
}

TEST(MetricsTest, TemporalErrorCountsOnlyChangeTheTruthDoesNotMake) {
    // Two pixels, three frames. Pixel 0 brightens by 51 a frame in both sequences (no error);
    // pixel 1 stays dark in the truth but the method's blinks 0 -> 255 -> 0 and its mask with
    // it: E_t = (255 + 255) / 255 over 3 channels x 2 pixels, per step of two.
    auto frame = [](std::uint8_t a, std::uint8_t b, std::uint8_t maskB) {
        return SequenceFrame{{a, a, a, 255, b, b, b, 255}, {1, maskB}};
    };
    const std::vector<SequenceFrame> truth = {frame(0, 0, 0), frame(51, 0, 0), frame(102, 0, 0)};
    const std::vector<SequenceFrame> method = {frame(0, 0, 0), frame(51, 255, 1), frame(102, 0, 0)};
    const TemporalMetrics same = compareSequences(truth, truth);
    EXPECT_EQ(same.temporalError, 0.0);
    EXPECT_EQ(same.maskFlicker, 0.0);
    EXPECT_EQ(same.psnrDb, 100.0);
    const TemporalMetrics blinking = compareSequences(method, truth);
    EXPECT_NEAR(blinking.temporalError, 3.0 / 6.0, 1e-12);  // each step: 3 channels of 1.0
    EXPECT_NEAR(blinking.maskFlicker, 0.5, 1e-12);          // one of two pixels each step
    EXPECT_THROW(compareSequences(method, {truth[0]}), std::invalid_argument);
}

TEST(MetricsTest, DownsamplingAveragesInLinearLight) {
    // A 2x2 block of black and white halves to linear 0.5: sRGB 188 (0.7354 x 255 rounded).
    const std::vector<std::uint8_t> fine = {0,   0,   0,   255, 255, 255, 255, 255,
                                            255, 255, 255, 255, 0,   0,   0,   255};
    const std::vector<std::uint8_t> coarse = downsampleSrgb(fine, 1, 1, 2);
    ASSERT_EQ(coarse.size(), 4u);
    EXPECT_EQ(coarse[0], 188);
    EXPECT_EQ(coarse[3], 255);
}

}  // namespace
}  // namespace subscan
