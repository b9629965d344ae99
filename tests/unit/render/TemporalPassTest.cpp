// The temporal filter's jitter without GL: Halton (2, 3) offsets, centred on the pixel.
#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "render/TemporalPass.h"

namespace subscan {
namespace {

TEST(TemporalPassTest, HaltonJitterMatchesTheRadicalInverses) {
    // Index 1: 1/2 and 1/3; index 2: 1/4 and 2/3; index 5 = 101 in base 2 (5/8), 12 in base 3
    // (2/3 + 1/9 = 7/9), each minus the pixel's centre.
    EXPECT_DOUBLE_EQ(haltonJitter(1).x, 0.0);
    EXPECT_DOUBLE_EQ(haltonJitter(1).y, 1.0 / 3.0 - 0.5);
    EXPECT_DOUBLE_EQ(haltonJitter(2).x, 0.25 - 0.5);
    EXPECT_DOUBLE_EQ(haltonJitter(2).y, 2.0 / 3.0 - 0.5);
    EXPECT_DOUBLE_EQ(haltonJitter(5).x, 5.0 / 8.0 - 0.5);
    EXPECT_DOUBLE_EQ(haltonJitter(5).y, 7.0 / 9.0 - 0.5);
}

TEST(TemporalPassTest, OffsetsStratifyEachAxis) {
    // The first 16 x offsets fall one in each sixteenth of the pixel and the first 9 y
    // offsets one in each ninth (what makes jittered frames a supersampled picture).
    std::set<int> columns, rows;
    for (unsigned i = 1; i <= 16; ++i) {
        const glm::dvec2 jitter = haltonJitter(i);
        ASSERT_GT(jitter.x, -0.5);
        ASSERT_LT(jitter.x, 0.5);
        columns.insert(static_cast<int>((jitter.x + 0.5) * 16));
        if (i <= 9) {
            // k / 9 in floating point may land a hair below k / 9.
            rows.insert(static_cast<int>((jitter.y + 0.5) * 9 + 1e-9));
        }
    }
    EXPECT_EQ(columns.size(), 16u);
    EXPECT_EQ(rows.size(), 9u);
}

}  // namespace
}  // namespace subscan
