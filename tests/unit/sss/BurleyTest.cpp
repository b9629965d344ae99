#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "sss/Burley.h"
#include "sss/ProfileFit.h"

namespace subscan {
namespace {

TEST(BurleyTest, ProfileIntegratesToTheAlbedo) {
    for (double albedo : {0.05, 0.3, 0.8, 1.0}) {
        for (double meanFreePath : {0.1, 1.0, 20.0}) {
            const BurleyChannel channel(albedo, meanFreePath);
            const BurleyProfile profile({albedo, albedo, albedo},
                                        {meanFreePath, meanFreePath, meanFreePath});
            const Rgb integral =
                profileEnergy([&](double radiusMm) { return profile.reflectance(radiusMm); });
            // ∫R 2πr dr = A·s/4·(1/s + 3/s) = A exactly. R·r² ∝ r near 0, so the quadrature's
            // range (from 10⁻⁶ mm) misses ≈ A·s·10⁻⁶ mm/2 ≤ 2e-5·A for ld = 0.1 mm; beyond
            // that the log-trapezoids are accurate to ~1e-12.
            EXPECT_NEAR(integral[0], albedo, 3e-5 * albedo) << albedo << " " << meanFreePath;
            EXPECT_DOUBLE_EQ(channel.albedo(), albedo);
        }
    }
}

TEST(BurleyTest, ShapeFollowsTheSearchlightFit) {
    // s = (1.9 − A + 3.5(A − 0.8)²)/ld: at A = 0.8 the quadratic term vanishes.
    EXPECT_DOUBLE_EQ(BurleyChannel(0.8, 2.0).shape(), (1.9 - 0.8) / 2.0);
    EXPECT_DOUBLE_EQ(burleySearchlightScaling(0.2), 1.9 - 0.2 + 3.5 * 0.36);
    // R(r) by hand at r = 1 mm for A = 0.5, ld = 1 mm: s = 1.9 − 0.5 + 3.5·0.09 = 1.715.
    const double s = 1.715;
    const double expected =
        0.5 * s * (std::exp(-s) + std::exp(-s / 3.0)) / (8.0 * std::numbers::pi);
    // Same arithmetic up to the order of operations.
    EXPECT_NEAR(BurleyChannel(0.5, 1.0).reflectance(1.0), expected, 1e-15);
}

TEST(BurleyTest, BadParametersAreErrors) {
    EXPECT_THROW(BurleyChannel(1.5, 1.0), Error);
    EXPECT_THROW(BurleyChannel(0.5, 0.0), Error);
    EXPECT_THROW(BurleyChannel(0.5, INFINITY), Error);
}

}  // namespace
}  // namespace subscan
