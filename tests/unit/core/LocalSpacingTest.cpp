#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "core/LocalSpacing.h"
#include "core/PointCloud.h"
#include "core/Spacing.h"

namespace subscan {
namespace {

/// Points on the plane z = 3: rows along x `along` apart, rows `across` apart in y, each point
/// given `copies` times.
PointCloud lines(int rows, int perRow, double along, double across, int copies = 1) {
    PointCloudBuilder builder({}, static_cast<std::size_t>(rows * perRow * copies));
    for (int copy = 0; copy < copies; ++copy) {
        for (int r = 0; r < rows; ++r) {
            for (int i = 0; i < perRow; ++i) {
                PointRecord record;
                record.position = {i * along, r * across, 3.0};
                builder.add(record);
            }
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

/// `count` uniformly random points on the unit square of the plane z = 0.
PointCloud randomPlane(int count, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    PointCloudBuilder builder({}, static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        PointRecord record;
        record.position = {unit(random), unit(random), 0.0};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

/// Whether point `index` of lines(rows, perRow, ...) lies `rowMargin` rows and `pointMargin`
/// points from every edge (where neighbourhoods are whole).
bool interior(std::size_t index, int rows, int perRow, int rowMargin, int pointMargin) {
    const int r = static_cast<int>(index) / perRow, i = static_cast<int>(index) % perRow;
    return r >= rowMargin && r < rows - rowMargin && i >= pointMargin && i < perRow - pointMargin;
}

TEST(LocalSpacingTest, RandomPointsMatchABruteForceReference) {
    // Uniform random points on a plane (whose spacings vary enough to leave the band around h
    // that counts as h) against the definition, evaluated by sorting every distance.
    const PointCloud cloud = randomPlane(1500, 9);
    const double h = estimateSpacing(cloud, cloud.size());
    const std::vector<glm::vec4> spacing = estimateLocalSpacing(cloud, h);

    const std::size_t n = cloud.size();
    std::vector<double> fourth(n);
    std::vector<std::array<std::size_t, 4>> nearest(n);
    std::vector<glm::dvec3> across(n);
    for (std::size_t i = 0; i < n; ++i) {
        std::vector<std::pair<double, std::size_t>> byDistance;
        for (std::size_t j = 0; j < n; ++j) {
            if (j != i) {
                byDistance.emplace_back(
                    glm::distance(glm::dvec3(cloud.positions[i]), glm::dvec3(cloud.positions[j])),
                    j);
            }
        }
        std::sort(byDistance.begin(), byDistance.end());
        fourth[i] = byDistance[3].first;
        for (int k = 0; k < 4; ++k) {
            nearest[i][k] = byDistance[k].second;
        }
        const glm::dvec3 p(cloud.positions[i]);
        const glm::dvec3 line = glm::normalize(glm::dvec3(cloud.positions[nearest[i][0]]) - p);
        for (const auto& [distance, j] : byDistance) {
            const glm::dvec3 offset = glm::dvec3(cloud.positions[j]) - p;
            if (std::abs(glm::dot(offset, line)) < 0.70710678 * distance) {
                across[i] = offset;
                break;
            }
        }
    }
    std::vector<double> smoothed(n);
    for (std::size_t i = 0; i < n; ++i) {
        std::array<double, 5> around{fourth[i], fourth[nearest[i][0]], fourth[nearest[i][1]],
                                     fourth[nearest[i][2]], fourth[nearest[i][3]]};
        std::sort(around.begin(), around.end());
        smoothed[i] = around[2];
    }
    std::vector<double> sorted = smoothed;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    const double median = sorted[n / 2];
    int snapped = 0, lines = 0;
    for (std::size_t i = 0; i < n; ++i) {
        double w = smoothed[i] / median;
        // Values within float rounding (1e-5) of the band's edges may fall either side.
        if (std::abs(w - 1.5) < 1e-5 || std::abs(w - 1.0 / 1.5) < 1e-5) {
            continue;
        }
        if (w > 1.0 / 1.5 && w < 1.5) {
            w = 1.0;
            ++snapped;
        }
        // Float positions against double: ~1e-6 relative in each distance.
        EXPECT_NEAR(spacing[i].w, w, 1e-4 * w) << i;
        const glm::dvec3 expected =
            glm::length(across[i]) / h > 2.0 * w ? across[i] / h : glm::dvec3(0.0);
        lines += glm::length(expected) > 0.0;
        for (int c = 0; c < 3; ++c) {
            // Float positions relative to the cloud's centre, divided by h ~ 0.01: 1e-3.
            EXPECT_NEAR(spacing[i][c], expected[c], 1e-3) << i;
        }
    }
    // Most points fall in the band around h (measured 1418), not all; some across vectors
    // occur.
    EXPECT_GT(snapped, 1000);
    EXPECT_LT(snapped, 1490);
    EXPECT_GT(lines, 5);
}

TEST(LocalSpacingTest, CancellingStopsTheEstimate) {
    // The viewer estimates a scan's local spacing after its first picture and drops the work
    // when another scan replaces it: the estimate asks, and stops at the first yes.
    const PointCloud cloud = randomPlane(40000, 3);
    std::atomic<int> asked{0};
    const std::vector<glm::vec4> stopped = estimateLocalSpacing(cloud, 0.01, [&] {
        ++asked;
        return true;
    });
    EXPECT_GE(asked.load(), 1);
    // Points the stopped work never reached keep the placeholder (w = 1, no across vector);
    // the finished estimate gives most of them another w.
    const std::vector<glm::vec4> finished = estimateLocalSpacing(cloud, 0.01, [] { return false; });
    ASSERT_EQ(stopped.size(), cloud.size());
    EXPECT_NE(stopped, finished);
    EXPECT_EQ(finished, estimateLocalSpacing(cloud, 0.01));
}

TEST(LocalSpacingTest, AnEvenGridHasTheGlobalSpacingAndNoLines) {
    const PointCloud cloud = lines(40, 40, 0.01, 0.01);
    const std::vector<glm::vec4> spacing = estimateLocalSpacing(cloud, estimateSpacing(cloud));
    ASSERT_EQ(spacing.size(), cloud.size());
    for (std::size_t i = 0; i < spacing.size(); ++i) {
        if (interior(i, 40, 40, 3, 3)) {
            // Inside, every point's 4th neighbour is one step away, as is the median's:
            // floats relative to the cloud's centre carry ~1e-6 relative error.
            EXPECT_NEAR(spacing[i].w, 1.0f, 1e-4f) << i;
            EXPECT_EQ(glm::vec3(spacing[i]), glm::vec3(0.0f)) << i;
        }
    }
}

/// Scan lines `ratio` times farther apart than their points: every inner point's across
/// vector is the gap to the next line, in units of h (the step along the lines), pointing
/// across them; its spacing w stays the one along its line.
void expectLinesFound(double ratio) {
    constexpr int kRows = 12, kPerRow = 300;
    constexpr double kAlong = 0.01;
    const PointCloud cloud = lines(kRows, kPerRow, kAlong, ratio * kAlong);
    const double h = estimateSpacing(cloud);
    ASSERT_NEAR(h, kAlong, 1e-7);  // the nearest neighbour lies along the line
    const std::vector<glm::vec4> spacing = estimateLocalSpacing(cloud, h);
    int checked = 0;
    for (std::size_t i = 0; i < spacing.size(); ++i) {
        // Every row has a neighbour row; two points from a row's end its 4th neighbour lies two
        // steps away as elsewhere.
        if (!interior(i, kRows, kPerRow, 0, 2)) {
            continue;
        }
        ++checked;
        // The 4th neighbour along a line lies 2 steps away, for every point alike.
        EXPECT_NEAR(spacing[i].w, 1.0f, 1e-4f) << i;
        // Float positions: ~1e-6 relative.
        EXPECT_NEAR(std::abs(spacing[i].y), ratio, 1e-3 * ratio) << i;
        EXPECT_NEAR(spacing[i].x, 0.0f, 1e-3f) << i;
        EXPECT_NEAR(spacing[i].z, 0.0f, 1e-3f) << i;
    }
    EXPECT_GT(checked, 1000);
}

TEST(LocalSpacingTest, LinesTenStepsApartAreFound) {
    expectLinesFound(10.0);
}

TEST(LocalSpacingTest, LinesThirtyStepsApartAreFoundByTheWiderSearch) {
    // 60 points of the own line lie nearer than the next one: past the first 12 neighbours.
    expectLinesFound(30.0);
}

TEST(LocalSpacingTest, ALineGapOfOneAndAHalfStepsIsNoScanLine) {
    const PointCloud cloud = lines(30, 30, 0.01, 0.015);
    const std::vector<glm::vec4> spacing = estimateLocalSpacing(cloud, estimateSpacing(cloud));
    for (std::size_t i = 0; i < spacing.size(); ++i) {
        if (interior(i, 30, 30, 3, 3)) {
            EXPECT_EQ(glm::vec3(spacing[i]), glm::vec3(0.0f)) << i;
        }
    }
}

TEST(LocalSpacingTest, RepeatedPointsAreLookedPast) {
    const PointCloud once = lines(12, 200, 0.01, 0.1);
    const PointCloud twice = lines(12, 200, 0.01, 0.1, 2);
    const std::vector<glm::vec4> single = estimateLocalSpacing(once, estimateSpacing(once));
    const std::vector<glm::vec4> doubled = estimateLocalSpacing(twice, estimateSpacing(twice));
    for (std::size_t i = 0; i < single.size(); ++i) {
        if (interior(i, 12, 200, 0, 2)) {
            // Both copies find the same neighbours (at equal distances the order may differ,
            // the lengths not).
            for (const std::size_t copy : {i, i + single.size()}) {
                // Float positions: ~1e-6 relative.
                EXPECT_NEAR(doubled[copy].w, single[i].w, 1e-4f) << i;
                EXPECT_NEAR(glm::length(glm::vec3(doubled[copy])),
                            glm::length(glm::vec3(single[i])), 1e-3f)
                    << i;
            }
        }
    }
}

/// A 40 x 40 patch of step 0.01 and, beside it, a 20 x 20 patch of step `sparseStep`.
PointCloud twoPatches(double sparseStep) {
    PointCloudBuilder builder({}, 40 * 40 + 20 * 20);
    for (int i = 0; i < 40; ++i) {
        for (int j = 0; j < 40; ++j) {
            PointRecord record;
            record.position = {i * 0.01, j * 0.01, 0.0};
            builder.add(record);
        }
    }
    for (int i = 0; i < 20; ++i) {
        for (int j = 0; j < 20; ++j) {
            PointRecord record;
            record.position = {5.0 + i * sparseStep, j * sparseStep, 0.0};
            builder.add(record);
        }
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

TEST(LocalSpacingTest, SpacingFollowsTheDensity) {
    // The second patch four times sparser: w is 4x as large there as in the first, relative
    // to the median (the dense patch holds more points, so the median is its).
    const PointCloud cloud = twoPatches(0.04);
    const std::vector<glm::vec4> spacing = estimateLocalSpacing(cloud, estimateSpacing(cloud));
    // Centres of each patch (float positions: 1e-4 relative).
    EXPECT_NEAR(spacing[20 * 40 + 20].w, 1.0f, 1e-4f);
    EXPECT_NEAR(spacing[1600 + 10 * 20 + 10].w, 4.0f, 4e-4f);
}

TEST(LocalSpacingTest, SpacingWithinAFactorOneAndAHalfOfHCountsAsH) {
    // 1.4 times sparser: an even scan's sampling noise, h itself; 1.6 times: a density.
    const PointCloud even = twoPatches(0.014);
    EXPECT_EQ(estimateLocalSpacing(even, estimateSpacing(even))[1600 + 10 * 20 + 10].w, 1.0f);
    const PointCloud uneven = twoPatches(0.016);  // float positions: ~1e-6 relative below
    EXPECT_NEAR(estimateLocalSpacing(uneven, estimateSpacing(uneven))[1600 + 10 * 20 + 10].w, 1.6f,
                2e-4f);
}

TEST(LocalSpacingTest, AStreamedLevelsPointsTakeAtLeastItsSpacing) {
    // Two levels of a streamed view side by side: points 0.01 apart for x < 0.6, 0.02 apart
    // beyond (a coarser level). The coarse points at the border find fine neighbours and
    // estimate a smaller spacing than the coarse level's 2 h; with their level given they
    // take at least the level's median estimate.
    PointCloudBuilder builder({}, 60 * 60 + 30 * 30);
    std::vector<float> levelSpacing;
    for (const double step : {0.01, 0.02}) {
        const int count = static_cast<int>(0.6 / step + 0.5);
        for (int i = 0; i < count; ++i) {
            for (int j = 0; j < count; ++j) {
                PointRecord record;
                record.position = {(step == 0.01 ? 0.0 : 0.6) + i * step, j * step, 0.0};
                builder.add(record);
                levelSpacing.push_back(static_cast<float>(step));
            }
        }
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const PointSpacing alone = estimatePointSpacing(cloud);
    const PointSpacing byLevel = estimatePointSpacing(cloud, levelSpacing);
    ASSERT_EQ(alone.local.size(), cloud.size());
    ASSERT_EQ(byLevel.local.size(), cloud.size());
    EXPECT_EQ(byLevel.global, alone.global);
    const std::size_t coarseMiddle = 3600 + 15 * 30 + 15, coarseAtBorder = 3600 + 15;
    // Float positions: w within 1e-4 of the steps' ratio.
    EXPECT_NEAR(alone.local[coarseMiddle].w, 2.0f, 2e-4f);
    EXPECT_LT(alone.local[coarseAtBorder].w, 1.9f) << "the border's coarse points look denser";
    EXPECT_NEAR(byLevel.local[coarseAtBorder].w, 2.0f, 2e-4f);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        EXPECT_GE(byLevel.local[i].w, alone.local[i].w) << i;  // never below the estimate
        EXPECT_EQ(glm::vec3(byLevel.local[i]), glm::vec3(alone.local[i])) << i;  // lines kept
    }
    // Points at the scan's own spacing (a node holding its whole cube: level spacing 0) keep
    // their estimate.
    std::vector<float> withWhole = levelSpacing;
    withWhole[coarseAtBorder] = 0.0f;
    EXPECT_EQ(estimatePointSpacing(cloud, withWhole).local[coarseAtBorder],
              alone.local[coarseAtBorder]);
    // One level, or none given: the estimate alone.
    const std::vector<float> one(cloud.size(), 0.01f);
    EXPECT_EQ(estimatePointSpacing(cloud, one).local, alone.local);
    EXPECT_EQ(estimatePointSpacing(cloud, std::span<const float>{}).local, alone.local);
    EXPECT_THROW(estimatePointSpacing(cloud, std::span(levelSpacing).first(10)),
                 std::invalid_argument);
}

TEST(LocalSpacingTest, TheSparsestAreCutToFourTimesWhatTheRestStayWithin) {
    // 10,000 entries at 1.5: the ratio that all but the sparsest 0.1 % stay within, whose
    // 4 times, 6, bounds every entry. An across vector is shortened along itself, w kept.
    std::vector<glm::vec4> spacing(10'000, glm::vec4(0.0f, 0.0f, 0.0f, 1.5f));
    spacing[10] = glm::vec4(0.0f, 0.0f, 0.0f, 40.0f);
    spacing[20] = glm::vec4(0.0f, 30.0f, 40.0f, 2.0f);
    spacing[30] = glm::vec4(0.0f, 0.0f, 0.0f, 5.9f);
    cutTheSparsest(spacing);
    EXPECT_EQ(spacing[10], glm::vec4(0.0f, 0.0f, 0.0f, 6.0f));
    EXPECT_NEAR(glm::distance(spacing[20], glm::vec4(0.0f, 3.6f, 4.8f, 2.0f)), 0.0f, 1e-6f);
    EXPECT_EQ(spacing[30], glm::vec4(0.0f, 0.0f, 0.0f, 5.9f));
    EXPECT_EQ(spacing[0], glm::vec4(0.0f, 0.0f, 0.0f, 1.5f));

    // Three points 150 spacings from a plane of grid points: their neighbours' distance would
    // make them reach that far; estimated, they reach no further than 4 times the plane's.
    PointCloudBuilder builder({}, 100 * 100 + 3);
    std::vector<float> levelSpacing;
    for (int i = 0; i < 100; ++i) {
        for (int j = 0; j < 100; ++j) {
            PointRecord record;
            record.position = {i * 0.001, j * 0.001, 0.0};
            builder.add(record);
            levelSpacing.push_back(0.001f);
        }
    }
    for (const double offset : {0.0, 0.0005, 0.0011}) {
        PointRecord record;
        record.position = {-0.15 + offset, 0.04, 0.0};
        builder.add(record);
        levelSpacing.push_back(0.001f);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const PointSpacing estimated = estimatePointSpacing(cloud);
    ASSERT_EQ(estimated.local.size(), cloud.size());
    for (std::size_t i = cloud.size() - 3; i < cloud.size(); ++i) {
        EXPECT_LE(estimated.local[i].w, kSparsestReach) << i;  // the plane's ratio is 1
    }
    // A streamed view's coarse level raises its points' w after the cut: a level 100 times
    // as sparse as the rest keeps its floor, or coarse levels would open up.
    for (std::size_t i = cloud.size() - 3; i < cloud.size(); ++i) {
        levelSpacing[i] = 0.1f;
    }
    const PointSpacing byLevel = estimatePointSpacing(cloud, levelSpacing);
    for (std::size_t i = cloud.size() - 3; i < cloud.size(); ++i) {
        EXPECT_GT(byLevel.local[i].w, 50.0f) << i;
    }
}

TEST(LocalSpacingTest, ALargeEvenStreamedViewGetsItsLevelsSpacingWithoutEstimates) {
    // Above kAlwaysLocalSpacingPoints an even cloud gets no local estimate; a streamed view of
    // it still needs its levels' spacings: w = the level's spacing over the dominant level's,
    // no scan lines.
    constexpr int kSide = 1500;  // 2.25 M points
    static_assert(kSide * kSide > kAlwaysLocalSpacingPoints);
    PointCloud cloud;
    cloud.positions.reserve(kSide * kSide);
    std::vector<float> levelSpacing;
    for (int i = 0; i < kSide; ++i) {
        for (int j = 0; j < kSide; ++j) {
            cloud.positions.emplace_back(i * 0.01f, j * 0.01f, 0.0f);
            cloud.bounds.add(glm::dvec3(cloud.positions.back()));
            levelSpacing.push_back(i < kSide / 2 ? 0.01f : i < kSide - 10 ? 0.04f : 0.0f);
        }
    }
    ASSERT_TRUE(estimatePointSpacing(cloud).local.empty());
    const PointSpacing spacing = estimatePointSpacing(cloud, levelSpacing);
    ASSERT_EQ(spacing.local.size(), cloud.size());
    for (const std::size_t i :
         {std::size_t{0}, std::size_t{kSide} * (kSide / 2) + 3, cloud.size() - 1}) {
        EXPECT_EQ(glm::vec3(spacing.local[i]), glm::vec3(0.0f)) << i;
    }
    EXPECT_EQ(spacing.local[0].w, 1.0f);                                     // the dominant level
    EXPECT_EQ(spacing.local[std::size_t{kSide} * (kSide / 2) + 3].w, 4.0f);  // 4 times sparser
    EXPECT_EQ(spacing.local.back().w, 1.0f);  // the scan's own spacing: no minimum
}

TEST(LocalSpacingTest, DegenerateCloudsKeepTheGlobalSpacing) {
    EXPECT_TRUE(estimateLocalSpacing(PointCloud{}, 1.0).empty());
    const PointCloud single = lines(1, 1, 1.0, 1.0);
    EXPECT_EQ(estimateLocalSpacing(single, 1.0), std::vector<glm::vec4>{glm::vec4(0, 0, 0, 1)});
    // One point given ten times: no neighbour at a distance.
    const PointCloud repeated = lines(1, 1, 1.0, 1.0, 10);
    for (const glm::vec4& entry : estimateLocalSpacing(repeated, 1.0)) {
        EXPECT_EQ(entry, glm::vec4(0, 0, 0, 1));
    }
}

TEST(LocalSpacingTest, VariationIsFoundInAStationsRangeNotInEvenOrRandomScans) {
    EXPECT_FALSE(spacingVaries(sampledNearestDistances(lines(100, 100, 0.01, 0.01))));
    // Uniformly random points on a plane: nearest distances follow a Rayleigh law, whose 90th
    // percentile is 4.7 times its 10th: the most uneven an even scan gets.
    EXPECT_FALSE(spacingVaries(sampledNearestDistances(randomPlane(20000, 3))));
    // Rows whose spacing grows 30-fold from first to last, as a station's with range.
    PointCloudBuilder station({}, 20000);
    for (int r = 0; r < 100; ++r) {
        const double step = 0.01 * std::pow(30.0, r / 99.0);
        for (int i = 0; i < 200; ++i) {
            PointRecord record;
            record.position = {i * step, r * 1.0, 0.0};
            station.add(record);
        }
    }
    std::vector<std::string> warnings;
    EXPECT_TRUE(spacingVaries(sampledNearestDistances(station.finish(warnings))));
}

TEST(LocalSpacingTest, PointSpacingTakesAGivenHAndEstimatesTheLocalOneForSmallClouds) {
    const PointCloud cloud = lines(20, 20, 0.01, 0.01);
    const PointSpacing given = estimatePointSpacing(cloud, 0.02);
    EXPECT_EQ(given.global, 0.02);
    ASSERT_EQ(given.local.size(), cloud.size());
    EXPECT_EQ(given.local, estimateLocalSpacing(cloud, 0.02));
    const PointSpacing estimated = estimatePointSpacing(cloud);
    EXPECT_NEAR(estimated.global, 0.01, 1e-7);  // float positions
    EXPECT_EQ(estimated.local.size(), cloud.size());
    const PointSpacing fromSample = estimatePointSpacing(cloud, sampleSpacing(cloud));
    EXPECT_EQ(fromSample.global, estimated.global);
    EXPECT_EQ(fromSample.local, estimated.local);
    // No h, no scale for the local spacing.
    EXPECT_TRUE(estimatePointSpacing(lines(1, 1, 1.0, 1.0)).local.empty());
}

}  // namespace
}  // namespace subscan
