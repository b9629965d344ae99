// Single scattering on the CPU (DESIGN.md §6.3): the boundary and phase terms against their
// definitions, the slab closed forms against direct integration of the radiative transfer
// integral, and the pass's estimator against the closed form: unbiased with random strata,
// close with the GPU's midpoint strata, and the often-quoted estimator shown biased.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "sss/SingleScattering.h"

namespace subscan {
namespace {

constexpr double kPi = std::numbers::pi;

glm::dvec3 direction(double thetaDegrees, double phiDegrees) {
    const double theta = thetaDegrees * kPi / 180.0, phi = phiDegrees * kPi / 180.0;
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

const glm::dvec3 kNormal{0.0, 0.0, 1.0};

TEST(SingleScatteringTest, FresnelTransmittanceAtNormalAndGrazingIncidence) {
    for (double eta : {1.3, 1.5}) {
        const double r0 = std::pow((eta - 1.0) / (eta + 1.0), 2.0);
        EXPECT_NEAR(fresnelTransmittance(1.0, eta), 1.0 - r0, 1e-12);
        EXPECT_NEAR(fresnelTransmittance(1e-9, eta), 0.0, 1e-6);
    }
    // Brewster's angle: the parallel reflectance vanishes, so T = 1 − Rs/2 with Rs from Snell.
    const double eta = 1.5, brewster = std::atan(eta);
    const double cosI = std::cos(brewster), cosT = refractedCosine(cosI, eta);
    const double rs = std::pow((cosI - eta * cosT) / (cosI + eta * cosT), 2.0);
    EXPECT_NEAR(fresnelTransmittance(cosI, eta), 1.0 - 0.5 * rs, 1e-12);
    EXPECT_DOUBLE_EQ(fresnelTransmittance(1.0, 1.0), 1.0);
}

TEST(SingleScatteringTest, RefractionFollowsSnell) {
    const glm::dvec3 in = direction(60.0, 30.0);
    const glm::dvec3 out = refractedDirection(in, kNormal, 1.5);
    EXPECT_NEAR(glm::length(out), 1.0, 1e-12);
    const double sinIn = std::sin(60.0 * kPi / 180.0);
    EXPECT_NEAR(std::sqrt(1.0 - out.z * out.z), sinIn / 1.5, 1e-12);
    EXPECT_NEAR(out.z, refractedCosine(in.z, 1.5), 1e-12);
    // The plane of incidence is kept: the tangential parts are parallel.
    EXPECT_NEAR(out.x * in.y - out.y * in.x, 0.0, 1e-12);
}

TEST(SingleScatteringTest, HenyeyGreensteinIsNormalisedAndHasMeanCosineG) {
    for (double g : {0.0, 0.5, -0.3, 0.9}) {
        // Midpoint rule over μ with 200000 steps: the g = 0.9 peak (width ~0.01) is resolved
        // to far better than the 1e-4 asked.
        constexpr int kSteps = 200000;
        double total = 0.0, mean = 0.0;
        for (int i = 0; i < kSteps; ++i) {
            const double mu = -1.0 + (i + 0.5) * 2.0 / kSteps;
            const double value = henyeyGreenstein(mu, g) * 2.0 * kPi * 2.0 / kSteps;
            total += value;
            mean += mu * value;
        }
        EXPECT_NEAR(total, 1.0, 1e-4) << "g " << g;
        EXPECT_NEAR(mean, g, 1e-4) << "g " << g;
    }
}

/// L_o = ∫₀^S σs w e^(−σt (s + s_i′(s))) ds by the midpoint rule on a fine grid, for a slab:
/// the definition the closed forms must agree with.
double integrateSlab(const ScatteringMedium& medium, const glm::dvec3& toLight,
                     const glm::dvec3& toEye, double thickness, bool backLit) {
    const double cosIn = std::abs(toLight.z), cosOut = toEye.z;
    const double cosInInside = refractedCosine(cosIn, medium.eta);
    const double cosOutInside = refractedCosine(cosOut, medium.eta);
    const double weight = singleScatteringGeometry(toLight, backLit ? -kNormal : kNormal, toEye,
                                                   kNormal, medium.eta, medium.g);
    const double length = std::isinf(thickness) ? 40.0 / medium.sigmaT() : thickness / cosOutInside;
    constexpr int kSteps = 400000;
    double total = 0.0;
    for (int i = 0; i < kSteps; ++i) {
        const double s = (i + 0.5) * length / kSteps;
        const double depth = s * cosOutInside;
        const double lightPath = (backLit ? thickness - depth : depth) / cosInInside;
        total += medium.sigmaS * weight * std::exp(-medium.sigmaT() * (s + lightPath));
    }
    return total * length / kSteps;
}

TEST(SingleScatteringTest, SlabClosedFormsMatchTheIntegral) {
    const ScatteringMedium medium{2.0, 0.3, 1.4, 0.4};
    for (const auto& [lightTheta, eyeTheta, phi] :
         {std::tuple{0.0, 0.0, 0.0}, {30.0, 50.0, 180.0}, {75.0, 10.0, 90.0}, {60.0, 60.0, 0.0}}) {
        const glm::dvec3 toLight = direction(lightTheta, 0.0);
        const glm::dvec3 toEye = direction(eyeTheta, phi);
        // 1e-6 relative: the midpoint rule's error with 400000 steps over an exponential.
        const double semi = semiInfiniteSlabRadiance(medium, kNormal, toLight, toEye, 1.0);
        EXPECT_NEAR(semi, integrateSlab(medium, toLight, toEye, INFINITY, false), 1e-6 * semi);
        const double front = frontLitSlabRadiance(medium, kNormal, toLight, toEye, 1.0, 0.4);
        EXPECT_NEAR(front, integrateSlab(medium, toLight, toEye, 0.4, false), 1e-6 * front);
        const glm::dvec3 fromBehind{toLight.x, toLight.y, -toLight.z};
        const double back = backLitSlabRadiance(medium, kNormal, fromBehind, toEye, 1.0, 0.4);
        EXPECT_NEAR(back, integrateSlab(medium, fromBehind, toEye, 0.4, true), 1e-6 * back);
        EXPECT_GT(back, 0.0);
    }
    // At normal incidence the back-lit slab is α T² p E σt d e^(−σt d)/η².
    const double t = fresnelTransmittance(1.0, medium.eta);
    const double d = 0.7;
    EXPECT_NEAR(backLitSlabRadiance(medium, kNormal, -kNormal, kNormal, 1.0, d),
                medium.albedo() * t * t * henyeyGreenstein(1.0, medium.g) * medium.sigmaT() * d *
                    std::exp(-medium.sigmaT() * d) / (medium.eta * medium.eta),
                1e-12);
}

TEST(SingleScatteringTest, SemiInfiniteSlabDoesNotDependOnTheExtinction) {
    const ScatteringMedium thin{0.5, 0.05, 1.3, 0.0};
    const ScatteringMedium dense{50.0, 5.0, 1.3, 0.0};  // the same albedo, 100x the extinction
    const glm::dvec3 toLight = direction(40.0, 0.0), toEye = direction(20.0, 120.0);
    EXPECT_NEAR(semiInfiniteSlabRadiance(thin, kNormal, toLight, toEye, 1.0),
                semiInfiniteSlabRadiance(dense, kNormal, toLight, toEye, 1.0), 1e-14);
}

/// The slab as the estimator sees it: the light enters the plane above each sample.
LightAtSample slabLight(const ScatteringMedium& medium, const glm::dvec3& toLight,
                        const glm::dvec3& toEye, double s) {
    const double depth = s * refractedCosine(toEye.z, medium.eta);
    return {singleScatteringGeometry(toLight, kNormal, toEye, kNormal, medium.eta, medium.g),
            depth / refractedCosine(toLight.z, medium.eta)};
}

TEST(SingleScatteringTest, EstimatorIsUnbiasedForAColouredMedium) {
    // Three channels with 1:4:16 extinction (a strongly coloured medium) and the light at 60°.
    const Rgb sigmaS{0.9, 3.5, 13.0}, sigmaA{0.1, 0.5, 3.0};
    const Rgb sigmaT{1.0, 4.0, 16.0};
    const glm::dvec3 toLight = direction(60.0, 0.0), toEye = direction(35.0, 200.0);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    constexpr int kTrials = 40000;
    Rgb mean{};
    Rgb quotedMean{};
    for (int trial = 0; trial < kTrials; ++trial) {
        const Rgb offsets{uniform(random), uniform(random), uniform(random)};
        for (int c = 0; c < 3; ++c) {
            const ScatteringMedium medium{sigmaS[c], sigmaA[c], 1.5, 0.5};
            const Rgb estimate = estimateSingleScattering(
                sigmaS, sigmaT, 4, offsets,
                [&](double s) { return slabLight(medium, toLight, toEye, s); });
            mean[c] += estimate[c] / kTrials;
            // The often-quoted form: s drawn from σt e^(−σt s) (one channel's own density) and
            // weighted by σs·F·p/σt · e^(−s_i′σt) · e^(−s σt).
            const double xi = uniform(random);
            const double s = -std::log1p(-xi) / sigmaT[c];
            const LightAtSample light = slabLight(medium, toLight, toEye, s);
            quotedMean[c] += sigmaS[c] * light.weight / sigmaT[c] *
                             std::exp(-sigmaT[c] * (light.lightPath + s)) / kTrials;
        }
    }
    for (int c = 0; c < 3; ++c) {
        const ScatteringMedium medium{sigmaS[c], sigmaA[c], 1.5, 0.5};
        const double exact = semiInfiniteSlabRadiance(medium, kNormal, toLight, toEye, 1.0);
        // The estimator's spread over random strata is under 15 % of the value per trial
        // (measured), so the mean of 40000 lies within 0.1 % (1.3 standard errors) of an
        // unbiased estimator's expectation; 0.5 % leaves room and still sees a bias of the
        // quoted form's size (over 25 %) or any wrong term.
        EXPECT_NEAR(mean[c], exact, 5e-3 * exact) << "channel " << c;
        // The quoted form estimates α F p / (2 + G) instead of α F p / (1 + G), with
        // G = cos θo′/cos θi′: the extinction along the view ray is counted twice.
        const double g = refractedCosine(toEye.z, 1.5) / refractedCosine(toLight.z, 1.5);
        EXPECT_NEAR(quotedMean[c], exact * (1.0 + g) / (2.0 + g), 0.02 * exact) << c;
        EXPECT_LT(quotedMean[c], 0.75 * exact) << c;
    }
}

TEST(SingleScatteringTest, MidpointStrataConvergeToTheSlab) {
    // The GPU's deterministic strata (offsets 1/2): a quadrature whose error falls with the
    // sample count. Worst errors measured over these angles and channels: 4.8 % at the pass's
    // default of 8 samples, 0.5 % at 24, 0.07 % at 63.
    const Rgb sigmaS{1.8, 2.0, 2.6}, sigmaA{0.02, 0.05, 0.4};
    const Rgb sigmaT{sigmaS[0] + sigmaA[0], sigmaS[1] + sigmaA[1], sigmaS[2] + sigmaA[2]};
    for (const auto& [lightTheta, eyeTheta] :
         {std::pair{0.0, 0.0}, {45.0, 30.0}, {80.0, 0.0}, {20.0, 70.0}}) {
        const glm::dvec3 toLight = direction(lightTheta, 0.0), toEye = direction(eyeTheta, 180.0);
        for (const auto& [samples, tolerance] : {std::pair{8, 0.06}, {24, 0.01}, {63, 0.002}}) {
            const Rgb estimate =
                estimateSingleScattering(sigmaS, sigmaT, samples, {0.5, 0.5, 0.5}, [&](double s) {
                    return slabLight({sigmaS[1], sigmaA[1], 1.3, 0.0}, toLight, toEye, s);
                });
            for (int c = 0; c < 3; ++c) {
                const ScatteringMedium medium{sigmaS[c], sigmaA[c], 1.3, 0.0};
                const double exact = semiInfiniteSlabRadiance(medium, kNormal, toLight, toEye, 1.0);
                EXPECT_NEAR(estimate[c], exact, tolerance * exact)
                    << samples << " samples, light " << lightTheta << "°, eye " << eyeTheta
                    << "°, channel " << c;
            }
        }
    }
}

}  // namespace
}  // namespace subscan
