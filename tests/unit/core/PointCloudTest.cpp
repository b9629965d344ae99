#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "core/PointCloud.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

PointRecord at(double x, double y, double z) {
    PointRecord record;
    record.position = {x, y, z};
    return record;
}

TEST(PointCloudTest, RecentresOnBoundsAndKeepsUtmPrecision) {
    // A 100 m wide scan at UTM northing 5.4e6: a float holding the absolute coordinate would
    // step by 0.5 m; relative to the centre it must step by about 4 micrometres.
    PointCloudBuilder builder({}, 3);
    builder.add(at(500000.001, 5400000.002, 10.0));
    builder.add(at(500100.003, 5400050.004, 12.5));
    builder.add(at(500050.0, 5400025.0, 11.0));
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(cloud.origin, cloud.bounds.center());
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(500000.001, 5400000.002, 10.0));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(500100.003, 5400050.004, 12.5));
    // Float spacing near 50 (the largest offset from the centre) is 2^-18 = 3.8e-6.
    EXPECT_NEAR(cloud.fileCoordinates(0).x, 500000.001, 4e-6);
    EXPECT_NEAR(cloud.fileCoordinates(1).y, 5400050.004, 4e-6);
    EXPECT_NEAR(cloud.fileCoordinates(2).z, 11.0, 4e-6);
}

TEST(PointCloudTest, ResidualsGiveBackTheFilesCoordinatesAndLeaveThePositionsAlone) {
    // 200 km of millimetres far from the origin: floats relative to the centre round by up to
    // 4 mm (and the first point's origin, then the centre, round twice). With residuals the file
    // coordinates come back to far less than the millimetre grid's half step; the positions the
    // renderer draws are bit for bit those of a builder that keeps none.
    std::mt19937 random(7);
    std::uniform_int_distribution<int> millimetres(0, 200'000'000);
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 1000; ++i) {
        points.emplace_back(400000.0 + 0.001 * millimetres(random),
                            5000000.0 + 0.001 * millimetres(random), 0.001 * (i % 977));
    }
    PointCloudBuilder plain({}, points.size());
    PointCloudBuilder exact({}, points.size());
    exact.keepPositionResiduals();
    for (const glm::dvec3& p : points) {
        plain.add(at(p.x, p.y, p.z));
        exact.add(at(p.x, p.y, p.z));
    }
    std::vector<std::string> warnings;
    const PointCloud floats = plain.finish(warnings);
    PointCloud cloud = exact.finish(warnings);
    EXPECT_EQ(cloud.positions, floats.positions);
    EXPECT_EQ(cloud.origin, floats.origin);
    ASSERT_EQ(cloud.positionResiduals.size(), points.size());
    double floatError = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            // Double sums of values about 5e6 round by 1e-9; the residual's float is finer.
            EXPECT_NEAR(cloud.fileCoordinates(i)[axis], points[i][axis], 1e-8);
            floatError =
                std::max(floatError, std::abs(floats.fileCoordinates(i)[axis] - points[i][axis]));
        }
    }
    EXPECT_GT(floatError, 0.0005);  // what the residuals are for
    // A millimetre grid needs them at this extent; so do doubles on no grid (a micrometre).
    cloud.coordinateStep = 0.001;
    keepResidualsWhereNeeded(cloud);
    EXPECT_TRUE(cloud.hasPositionResiduals());
    // A grid of 10 m is kept by the floats alone: no memory is spent on residuals.
    cloud.coordinateStep = 10.0;
    keepResidualsWhereNeeded(cloud);
    EXPECT_FALSE(cloud.hasPositionResiduals());
    EXPECT_EQ(cloud.positionResiduals.capacity(), 0u);
}

TEST(PointCloudTest, ResidualsOfASmallScanAreDropped) {
    // A 2 m object scan of doubles: floats relative to the centre keep 0.1 micrometre, finer
    // than kDoubleCoordinateTolerance, so the cloud keeps no residuals.
    PointCloudBuilder builder({}, 3);
    builder.keepPositionResiduals();
    builder.add(at(0.123456789, 1.0, -1.0));
    builder.add(at(2.0, 0.333333333333, 0.0));
    builder.add(at(1.0, 0.5, 0.7777777777));
    std::vector<std::string> warnings;
    PointCloud cloud = builder.finish(warnings);
    cloud.doubleCoordinates = true;
    ASSERT_TRUE(cloud.hasPositionResiduals());
    keepResidualsWhereNeeded(cloud);
    EXPECT_FALSE(cloud.hasPositionResiduals());
}

TEST(PointCloudTest, DropsNonFinitePointsWithTheirAttributes) {
    PointCloudBuilder builder({.color = true, .intensity = true}, 4);
    PointRecord a = at(1, 2, 3);
    a.color = {1, 2, 3, 4};
    a.intensity = 5;
    PointRecord bad = at(NAN, 0, 0);
    bad.color = {9, 9, 9, 9};
    PointRecord b = at(4, 5, 6);
    b.color = {7, 8, 9, 10};
    b.intensity = 11;
    builder.add(a);
    builder.add(bad);
    builder.add(at(0, INFINITY, 0));
    builder.add(b);
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    ASSERT_EQ(cloud.size(), 2u);
    EXPECT_EQ(cloud.colors, (std::vector<Rgba8>{{1, 2, 3, 4}, {7, 8, 9, 10}}));
    EXPECT_EQ(cloud.intensities, (std::vector<float>{5, 11}));
    EXPECT_TRUE(cloud.normals.empty());
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_THAT(warnings[0], HasSubstr("dropped 2 of 4 points"));
}

TEST(PointCloudTest, AbsurdCoordinatesAreDroppedLikeNan) {
    // A finite double beyond float range would make the float position undefined behaviour.
    PointCloudBuilder builder({}, 3);
    builder.add(at(1, 2, 3));
    builder.add(at(1e300, 0, 0));
    builder.add(at(0, -2e15, 0));
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    EXPECT_EQ(cloud.size(), 1u);
    EXPECT_THAT(warnings, ::testing::Contains(HasSubstr("dropped 2 of 3 points")));
}

TEST(PointCloudTest, TrianglesFollowKeptVerticesAndLoseDroppedOnes) {
    PointCloudBuilder builder({}, 5, /*mapVertexIndices=*/true);
    builder.add(at(0, 0, 0));
    builder.add(at(NAN, 0, 0));  // file vertex 1 is dropped
    builder.add(at(1, 0, 0));
    builder.add(at(0, 1, 0));
    builder.addTriangle({0, 2, 3});
    builder.addTriangle({1, 2, 3});
    builder.addTriangle({3, 2, 0});
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    EXPECT_EQ(cloud.triangles, (std::vector<Triangle>{{0, 1, 2}, {2, 1, 0}}));
    EXPECT_THAT(warnings, ::testing::Contains(HasSubstr("dropped 1 faces")));
}

TEST(PointCloudTest, EmptyAndAllInvalidCloudsAreErrors) {
    std::vector<std::string> warnings;
    PointCloudBuilder empty({}, 0);
    EXPECT_THROW(
        {
            try {
                empty.finish(warnings);
            } catch (const Error& error) {
                EXPECT_THAT(error.what(), HasSubstr("contains no points"));
                throw;
            }
        },
        Error);
    PointCloudBuilder invalid({}, 2);
    invalid.add(at(NAN, NAN, NAN));
    invalid.add(at(-INFINITY, 0, 0));
    EXPECT_THROW(
        {
            try {
                invalid.finish(warnings);
            } catch (const Error& error) {
                EXPECT_THAT(error.what(), HasSubstr("all 2 points have NaN or infinite"));
                throw;
            }
        },
        Error);
}

TEST(PointCloudTest, FramingBoundsLeaveStrayPointsOut) {
    // 20,000 points in the box (10..11, 20..22, 30..33) and 5 strays 1000 units away: the
    // framing box is the dense box within its sampling (a 0.1 % quantile of uniform
    // coordinates lies 0.1 % of the side inside), the bounds hold the strays.
    std::mt19937 random(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    PointCloudBuilder builder({}, 20005);
    for (int i = 0; i < 20000; ++i) {
        builder.add(at(10 + unit(random), 20 + 2 * unit(random), 30 + 3 * unit(random)));
    }
    for (int i = 0; i < 5; ++i) {
        builder.add(at(1000, -1000, 1000));
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const Bounds framed = framingBounds(cloud);
    const glm::dvec3 low(10, 20, 30), side(1, 2, 3);
    for (int axis = 0; axis < 3; ++axis) {
        // 0.1 % of the side inside, give or take sampling (2 % of a side) and float storage.
        EXPECT_NEAR(framed.min[axis], low[axis] + 0.001 * side[axis], 0.02 * side[axis]);
        EXPECT_NEAR(framed.max[axis], low[axis] + 0.999 * side[axis], 0.02 * side[axis]);
    }
    EXPECT_EQ(cloud.bounds.max.x, 1000.0);
    // A small cloud keeps its exact bounds: 0.1 % of it is not a point.
    PointCloudBuilder small({}, 3);
    small.add(at(0, 0, 0));
    small.add(at(1, 1, 1));
    small.add(at(500, 0, 0));
    const PointCloud few = small.finish(warnings);
    EXPECT_EQ(framingBounds(few).max.x, few.bounds.max.x);
}

}  // namespace
}  // namespace subscan
