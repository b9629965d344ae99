#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "sss/Dipole.h"
#include "sss/MaterialLibrary.h"
#include "sss/ProfileFit.h"

namespace subscan {
namespace {

const char* const kChannel[] = {"red", "green", "blue"};

/// The Jensen materials whose fits have promised qualities: all but Spectralon, whose 1/r³ tail
/// (it does not absorb) no sum of Gaussians follows far out.
std::vector<const Material*> fittedMaterials() {
    std::vector<const Material*> materials;
    for (const Material& material : materialLibrary()) {
        if (material.sigmaSPrime && material.name != "spectralon") {
            materials.push_back(&material);
        }
    }
    return materials;
}

void expectValidSet(const GaussianSet& set, int count, const std::string& context) {
    ASSERT_EQ(set.gaussians.size(), static_cast<std::size_t>(count)) << context;
    EXPECT_FALSE(set.cumulative);
    for (std::size_t i = 0; i < set.gaussians.size(); ++i) {
        EXPECT_GT(set.gaussians[i].varianceMm2, 0.0) << context;
        if (i > 0) {
            EXPECT_GE(set.gaussians[i].varianceMm2, set.gaussians[i - 1].varianceMm2) << context;
        }
        for (double weight : set.gaussians[i].weight) {
            EXPECT_GE(weight, 0.0) << context;
        }
    }
    for (double sum : set.weightSums()) {
        // The weights are renormalised after the solve: only rounding remains.
        EXPECT_NEAR(sum, 1.0, 1e-12) << context;
    }
}

TEST(ProfileFitTest, JensenDipolesFitWithinTheirBudgets) {
    for (const Material* material : fittedMaterials()) {
        const RadialProfile profile = diffusionProfile(*material, ProfileModel::Dipole);
        // The budgets: an independent fit of the same profiles reached 0.046 (4 Gaussians) and
        // 0.009 (6) in its worst channel; these thresholds fail a fitter stuck in a worse
        // minimum. This one measures 0.046 and 0.0087, both Skimmilk's red.
        for (const auto& [count, budget] : {std::pair{4, 0.05}, std::pair{6, 0.01}}) {
            const ProfileFit fit = fitGaussians(profile, count);
            const std::string context = material->name + " with " + std::to_string(count);
            expectValidSet(fit.gaussians, count, context);
            for (int c = 0; c < 3; ++c) {
                EXPECT_LE(fit.quality.fitError[c], budget) << context << " " << kChannel[c];
            }
            // measureFit scores the returned set the way the fit did.
            const FitQuality measured = measureFit(profile, fit.gaussians);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(measured.fitError[c], fit.quality.fitError[c], 1e-12) << context;
            }
            EXPECT_DOUBLE_EQ(measured.rMaxMm, fit.quality.rMaxMm);
        }
    }
}

TEST(ProfileFitTest, RecoversAKnownSumOfGaussians) {
    // A profile that is exactly 3 Gaussians (different weights per channel) is found again.
    GaussianSet truth;
    truth.gaussians = {{0.05, {0.6, 0.2, 0.1}}, {0.8, {0.3, 0.5, 0.2}}, {6.0, {0.1, 0.3, 0.7}}};
    const RadialProfile profile = [&](double radiusMm) { return truth.evaluate(radiusMm); };
    const ProfileFit fit = fitGaussians(profile, 3);
    expectValidSet(fit.gaussians, 3, "three Gaussians");
    for (std::size_t i = 0; i < 3; ++i) {
        // The objective is zero there and Gauss–Newton converges quadratically onto it: the
        // measured parameters agree to ~1e-12; 1e-6 leaves room for other compilers' rounding.
        EXPECT_NEAR(fit.gaussians.gaussians[i].varianceMm2 / truth.gaussians[i].varianceMm2, 1.0,
                    1e-6);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(fit.gaussians.gaussians[i].weight[c], truth.gaussians[i].weight[c], 1e-6);
        }
    }
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(fit.quality.fitError[c], 1e-6);  // measured ~1e-12
    }
}

TEST(ProfileFitTest, RMaxHoldsTheWidestChannelsEnergy) {
    // One Gaussian per channel: 99.9 % of G(v) lies within r = √(2v ln 1000). The widest
    // channel (v = 4) sets rMax. The energy is summed over nodes 1/50 decade apart, taken as
    // exponential in ln r between them; a Gaussian's log is quadratic there, which leaves
    // 3.5e-4 relative.
    const RadialProfile profile = [](double radiusMm) {
        GaussianSet set;
        set.gaussians = {{0.1, {1.0, 0.0, 0.0}}, {1.0, {0.0, 1.0, 0.0}}, {4.0, {0.0, 0.0, 1.0}}};
        return set.evaluate(radiusMm);
    };
    const double expected = std::sqrt(8.0 * std::log(1000.0));
    EXPECT_NEAR(measureFit(profile, GaussianSet{}).rMaxMm / expected, 1.0, 1e-3);
}

TEST(ProfileFitTest, IsDeterministic) {
    const RadialProfile profile = diffusionProfile(findMaterial("skin1"), ProfileModel::Dipole);
    const ProfileFit first = fitGaussians(profile, 5);
    const ProfileFit second = fitGaussians(profile, 5);
    for (std::size_t i = 0; i < first.gaussians.gaussians.size(); ++i) {
        EXPECT_EQ(first.gaussians.gaussians[i].varianceMm2,
                  second.gaussians.gaussians[i].varianceMm2);
        EXPECT_EQ(first.gaussians.gaussians[i].weight, second.gaussians.gaussians[i].weight);
    }
}

TEST(ProfileFitTest, BurleyProfilesFitToo) {
    const RadialProfile profile = diffusionProfile(findMaterial("skin1"), ProfileModel::Burley);
    const ProfileFit fit = fitGaussians(profile, 6);
    expectValidSet(fit.gaussians, 6, "skin1 Burley");
    // No budget: R ∝ 1/r at the centre makes ∫R² r dr diverge logarithmically, so fit_error
    // depends on where the grid starts. It must still be a fit, not noise.
    for (int c = 0; c < 3; ++c) {
        EXPECT_LT(fit.quality.fitError[c], 0.5);
    }
    EXPECT_THROW(diffusionProfile(findMaterial("spectralon"), ProfileModel::Burley), Error);
}

TEST(ProfileFitTest, BadRequestsAreErrors) {
    const RadialProfile profile = diffusionProfile(findMaterial("skin1"), ProfileModel::Dipole);
    EXPECT_THROW(fitGaussians(profile, 0), Error);
    EXPECT_THROW(fitGaussians(profile, kMaxFittedGaussians + 1), Error);
    EXPECT_THROW(diffusionProfile(findMaterial("skin-deon"), ProfileModel::Dipole), Error);
    // A channel without energy cannot be normalised.
    EXPECT_THROW(fitGaussians(
                     [](double r) {
                         return Rgb{std::exp(-r), 0.0, std::exp(-r)};
                     },
                     2),
                 Error);
    // Energy far beyond 10⁶ mm (a 1/r² tail holds equal energy per decade).
    EXPECT_THROW(profileEnergy([](double r) { return Rgb{1.0 / (1.0 + r * r), 1.0, 1.0}; }), Error);
    EXPECT_THROW(profileEnergy([](double) { return Rgb{NAN, 1.0, 1.0}; }), Error);
}

}  // namespace
}  // namespace subscan
