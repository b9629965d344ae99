#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/PointCloud.h"
#include "core/Spacing.h"

namespace subscan {
namespace {

PointCloud gridPlane(int side, double step, int copies = 1) {
    PointCloudBuilder builder({}, static_cast<std::size_t>(side * side * copies));
    for (int copy = 0; copy < copies; ++copy) {
        for (int i = 0; i < side; ++i) {
            for (int j = 0; j < side; ++j) {
                PointRecord record;
                record.position = {1000.0 + i * step, -50.0 + j * step, 7.0};
                builder.add(record);
            }
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

TEST(SpacingTest, RegularGridGivesItsStep) {
    // Every nearest neighbour on a square grid is exactly one step away; floats relative to the
    // centre carry about 1e-7 relative error.
    EXPECT_NEAR(estimateSpacing(gridPlane(200, 0.01)), 0.01, 1e-7);
}

TEST(SpacingTest, DuplicatePointsAreLookedPast) {
    // Two copies of every point (overlapping range scans): the spacing is still the grid step.
    EXPECT_NEAR(estimateSpacing(gridPlane(60, 0.5, 2)), 0.5, 1e-6);
}

TEST(SpacingTest, SampledEstimateMatchesTheFullMedianOnJitteredPoints) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    PointCloudBuilder builder({}, 90000);
    for (int i = 0; i < 300; ++i) {
        for (int j = 0; j < 300; ++j) {
            PointRecord record;
            record.position = {i + jitter(random), j + jitter(random), jitter(random)};
            builder.add(record);
        }
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const double full = estimateSpacing(cloud, cloud.size());
    const double sampled = estimateSpacing(cloud, 5000);
    // 5000 samples estimate a median with a standard error of about 1.25/sqrt(5000) of the
    // spread of NN distances (~0.3 here), i.e. ~0.005; 0.02 is four standard errors.
    EXPECT_NEAR(sampled, full, 0.02);
    EXPECT_GT(full, 0.5);  // jitter only moves neighbours within +-0.4 of the unit step
    EXPECT_LT(full, 1.0);
}

TEST(SpacingTest, DegenerateCloudsGiveZero) {
    EXPECT_EQ(estimateSpacing(gridPlane(1, 1.0)), 0.0);
    EXPECT_EQ(estimateSpacing(gridPlane(1, 1.0, 5)), 0.0);  // five copies of one point
}

}  // namespace
}  // namespace subscan
