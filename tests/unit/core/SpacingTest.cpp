#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "core/PointCloud.h"
#include "core/Spacing.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::cloudOf;

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

/// The nearest non-coincident distance of each query point i·n/samples, by brute force in
/// double (infinity where there is none): the definition the header states, independently of
/// the search structures. A loop without calls (glm's operators, iterators, std::min): the
/// sanitized build compiles tests without optimisation, where each of those is one.
std::vector<double> bruteForceNearest(const PointCloud& cloud, std::size_t samples) {
    std::vector<double> nearest;
    const glm::vec3* points = cloud.positions.data();
    const std::size_t count = cloud.size();
    for (std::size_t s = 0; s < samples; ++s) {
        const glm::vec3 query = points[s * count / samples];
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < count; ++i) {
            const double dx = double(points[i].x) - double(query.x);
            const double dy = double(points[i].y) - double(query.y);
            const double dz = double(points[i].z) - double(query.z);
            const double squared = dx * dx + dy * dy + dz * dz;
            if (squared > 0.0 && squared < best) {
                best = squared;
            }
        }
        nearest.push_back(std::sqrt(best));
    }
    return nearest;
}

TEST(SpacingTest, SampledQueriesFindTheirExactNearestNeighbourInTheWholeCloud) {
    // Shapes that stress the grid search's cell size: a volume, a surface, a line (whose queries
    // lie hundreds of spacings apart), a dense cluster with isolated points (which need the
    // larger cells of later passes), with points farther still, and repeated points.
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const auto generate = [&](std::size_t count, auto&& position) {
        std::vector<glm::dvec3> positions;
        for (std::size_t i = 0; i < count; ++i) {
            positions.push_back(position(i));
        }
        return cloudOf(positions);
    };
    const std::vector<std::pair<const char*, PointCloud>> clouds = {
        {"volume", generate(60000,
                            [&](std::size_t) {
                                return glm::dvec3(unit(random), unit(random), unit(random)) * 10.0;
                            })},
        {"surface", generate(60000,
                             [&](std::size_t) {
                                 const double x = unit(random) * 4.0, y = unit(random) * 4.0;
                                 return glm::dvec3(x, y,
                                                   0.3 * std::sin(3.0 * x) * std::cos(2.0 * y));
                             })},
        {"line", generate(60000,
                          [&](std::size_t i) {
                              return glm::dvec3(i * 0.001 + unit(random) * 1e-4, 0.0, 0.0);
                          })},
        {"cluster with outliers",
         generate(60000,
                  [&](std::size_t i) {
                      const glm::dvec3 inCluster(unit(random), unit(random), unit(random));
                      return i % 50 == 0 ? inCluster * 1000.0 : inCluster * 0.5;
                  })},
        {"far outliers", generate(60000,
                                  [&](std::size_t i) {
                                      // Beyond the cells' growth over the passes: the k-d tree's
                                      // turn.
                                      const glm::dvec3 inCluster(unit(random), unit(random),
                                                                 unit(random));
                                      return i % 5000 == 0 ? inCluster * 10000.0 : inCluster * 0.5;
                                  })},
        {"every point four times",
         generate(60000,
                  [&](std::size_t i) {
                      // Overlapping range images: each position again 15000 points later.
                      const std::size_t original = i % 15000;
                      return glm::dvec3(original % 120, original / 120, (original * 7) % 3) * 0.01;
                  })},
    };
    for (const auto& [name, cloud] : clouds) {
        constexpr std::size_t kSamples = 700;
        const std::vector<double> expected = bruteForceNearest(cloud, kSamples);
        const std::vector<float> found = sampledNearestDistances(cloud, kSamples);
        ASSERT_EQ(found.size(), kSamples) << name;
        int wrong = 0;
        for (std::size_t q = 0; q < kSamples; ++q) {
            // Positions are floats about the centre and the search works in float: 1e-6
            // relative is a few float roundings of one distance.
            wrong += std::abs(found[q] - expected[q]) > 1e-6 * expected[q] ? 1 : 0;
        }
        EXPECT_EQ(wrong, 0) << name;
        std::vector<double> finite = expected;
        std::nth_element(finite.begin(), finite.begin() + kSamples / 2, finite.end());
        EXPECT_NEAR(estimateSpacing(cloud, kSamples), finite[kSamples / 2],
                    1e-6 * finite[kSamples / 2])
            << name;
    }
}

}  // namespace
}  // namespace subscan
