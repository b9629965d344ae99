// The blur chain the scattering pass runs, without GL: which Gaussian blurs what, by how much.
#include <cmath>

#include <gtest/gtest.h>

#include "render/SubsurfaceScatteringPass.h"

namespace subscan {
namespace {

using Chain = SubsurfaceScatteringPass::BlurChain;

TEST(SubsurfaceScatteringPassTest, IndependentGaussiansEachBlurTheSource) {
    GaussianSet set;
    set.gaussians = {{4.0, {0.5, 0.25, 0.0}}, {1.0, {0.5, 0.75, 1.0}}};
    // Scale 2 doubles sigma; 10 mm per unit (cm) divides it by 10.
    const Chain chain = SubsurfaceScatteringPass::blurChain(set, 2.0, 10.0);
    ASSERT_EQ(chain.steps.size(), 2u);
    EXPECT_DOUBLE_EQ(chain.steps[0].sigma, 1.0 * 2.0 / 10.0);  // sorted: v = 1 first
    EXPECT_DOUBLE_EQ(chain.steps[1].sigma, 2.0 * 2.0 / 10.0);
    EXPECT_FALSE(chain.steps[0].fromPrevious);
    EXPECT_FALSE(chain.steps[1].fromPrevious);
    EXPECT_FLOAT_EQ(chain.steps[1].weight[1], 0.25f);
    EXPECT_FLOAT_EQ(chain.unblurredWeight[0], 0.0f);
}

TEST(SubsurfaceScatteringPassTest, CumulativeSetsBlurOnByTheVarianceIncrement) {
    GaussianSet set;
    set.cumulative = true;
    set.gaussians = {{0.0, {0.25, 0.5, 0.75}}, {1.0, {0.25, 0.5, 0.25}}, {5.0, {0.5, 0.0, 0.0}}};
    const Chain chain = SubsurfaceScatteringPass::blurChain(set, 1.0, 1.0);
    EXPECT_FLOAT_EQ(chain.unblurredWeight[0], 0.25f);  // the zero variance is not blurred
    EXPECT_FLOAT_EQ(chain.unblurredWeight[2], 0.75f);
    ASSERT_EQ(chain.steps.size(), 2u);
    EXPECT_FALSE(chain.steps[0].fromPrevious);  // the first blur starts from the light
    EXPECT_DOUBLE_EQ(chain.steps[0].sigma, 1.0);
    EXPECT_TRUE(chain.steps[1].fromPrevious);
    EXPECT_DOUBLE_EQ(chain.steps[1].sigma, 2.0);  // sqrt(5 - 1): variances add up to 5
}

TEST(SubsurfaceScatteringPassTest, ScaleZeroLeavesTheLightUnblurred) {
    GaussianSet set;
    set.gaussians = {{1.0, {0.5, 0.5, 0.5}}, {2.0, {0.5, 0.5, 0.5}}};
    const Chain chain = SubsurfaceScatteringPass::blurChain(set, 0.0, 1.0);
    EXPECT_TRUE(chain.steps.empty());
    EXPECT_FLOAT_EQ(chain.unblurredWeight[1], 1.0f);
}

}  // namespace
}  // namespace subscan
