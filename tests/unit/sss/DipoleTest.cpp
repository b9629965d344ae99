#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "sss/Dipole.h"
#include "sss/MaterialLibrary.h"
#include "sss/ProfileFit.h"

namespace subscan {
namespace {

const char* const kChannel[] = {"red", "green", "blue"};

bool measured(const Material& material) {
    return material.sigmaSPrime && material.sigmaA;
}

TEST(DipoleTest, BoundaryTermsMatchIndependentValues) {
    // Reference values from Python's math module (double precision) evaluating DESIGN §6.2's
    // F_dr and A; the library does the same arithmetic, so only rounding separates them.
    EXPECT_NEAR(diffuseFresnelReflectance(1.3), 0.4448450887573965, 1e-15);
    EXPECT_NEAR(boundaryReflectionParameter(1.3), 2.602598048756155, 1e-14);
    EXPECT_NEAR(boundaryReflectionParameter(1.5), 3.960454157136166, 1e-14);
    // A matched boundary reflects (almost) nothing back: the fit gives F_dr = 0.0017 at η = 1.
    EXPECT_NEAR(diffuseFresnelReflectance(1.0), 0.0017, 1e-15);
    EXPECT_THROW(diffuseFresnelReflectance(0.9), Error);
}

TEST(DipoleTest, TotalReflectanceMatchesIndependentValues) {
    // Python, as above. These pin √(3(1 − α′)): the known slip √(3·1 − α′) gives 0.1063
    // instead of 0.2991 at α′ = 0.9.
    EXPECT_NEAR(totalDiffuseReflectance(0.1, 1.3), 0.009700612501691705, 1e-15);
    EXPECT_NEAR(totalDiffuseReflectance(0.5, 1.3), 0.07450596239970708, 1e-15);
    EXPECT_NEAR(totalDiffuseReflectance(0.9, 1.3), 0.2991140031023451, 1e-15);
    EXPECT_NEAR(totalDiffuseReflectance(0.99, 1.3), 0.6444973594119497, 1e-15);
    EXPECT_NEAR(totalDiffuseReflectance(0.999, 1.5), 0.8269859750969494, 1e-15);
    EXPECT_DOUBLE_EQ(totalDiffuseReflectance(1.0, 1.3), 1.0);
    EXPECT_DOUBLE_EQ(totalDiffuseReflectance(0.0, 1.3), 0.0);
}

TEST(DipoleTest, TotalReflectanceReproducesJensensTable) {
    int checked = 0;
    for (const Material& material : materialLibrary()) {
        if (!measured(material)) {
            continue;
        }
        const Rgb computed =
            DipoleProfile(*material.sigmaSPrime, *material.sigmaA, material.eta).totalReflectance();
        for (int c = 0; c < 3; ++c) {
            // The table prints two digits (±0.005) and was computed by Jensen et al. with their
            // own rounding of σs′ and σa: 35 of the 36 entries agree within 0.008 (measured
            // 2026-12-03: at most 0.0077, skimmilk's blue; median 0.003). Chicken1's blue does
            // not: 0.1264 against a printed 0.10. Half a unit in the last digit of its σs′ (0.38)
            // and σa (0.19) moves α′ by 0.009 and R_d by ~0.004; with the printing that is ~0.01,
            // not 0.026. It is the same 0.10 as chicken2's blue (which computes to 0.108): likely
            // a misprint, so this entry alone gets 0.027.
            const bool misprint = material.name == "chicken1" && c == 2;
            EXPECT_NEAR(computed[c], (*material.rd)[c], misprint ? 0.027 : 0.008)
                << material.name << " " << kChannel[c];
        }
        ++checked;
    }
    EXPECT_EQ(checked, 12);
}

TEST(DipoleTest, ProfileIntegratesToTheClosedForm) {
    for (const Material& material : materialLibrary()) {
        if (!measured(material)) {
            continue;
        }
        const DipoleProfile dipole(*material.sigmaSPrime, *material.sigmaA, material.eta);
        const Rgb integral =
            profileEnergy([&](double radiusMm) { return dipole.reflectance(radiusMm); });
        const Rgb closedForm = dipole.totalReflectance();
        for (int c = 0; c < 3; ++c) {
            // Exact in theory (each source integrates to 2π e^{−σtr z}). Numerically: trapezoids
            // in ln r at 50 nodes per decade converge faster than any power for these smooth
            // integrands (measured ≤ 2e-14 relative), and the range ends at 10⁶ mm, beyond which
            // Spectralon's non-absorbing 1/r³ tail still holds ~2e-7 of its energy.
            EXPECT_NEAR(integral[c] / closedForm[c], 1.0, 1e-6)
                << material.name << " " << kChannel[c];
        }
    }
}

TEST(DipoleTest, ProfileAtTheCentreIsTheSourcesSum) {
    // At r = 0, d = z: R_d(0) = α′/(4π)·Σ (σtr z + 1) e^{−σtr z} / z², evaluated here by hand
    // for skin1's red (σs′ = 0.74, σa = 0.032, η = 1.3).
    const double extinction = 0.772;
    const double albedo = 0.74 / extinction;
    const double sigmaTr = std::sqrt(3.0 * 0.032 * extinction);
    const double zr = 1.0 / extinction;
    const double zv = zr * (1.0 + 4.0 / 3.0 * 2.602598048756155);
    auto source = [&](double z) { return (sigmaTr * z + 1.0) * std::exp(-sigmaTr * z) / (z * z); };
    const double expected = albedo / (4.0 * std::numbers::pi) * (source(zr) + source(zv));
    // Same formula, different order of operations: a few ulps.
    EXPECT_NEAR(DipoleChannel(0.74, 0.032, 1.3).reflectance(0.0), expected, 1e-14 * expected);
}

TEST(DipoleTest, ReducedAlbedoInversionRoundTrips) {
    for (double eta : {1.0, 1.3, 1.5}) {
        const ReducedAlbedoTable table(eta);
        for (double albedo : {0.0, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.95, 0.99, 0.995}) {
            // Linear interpolation over 4096 entries in u = √(1 − α′), where R_d is smooth: the
            // error is ~h²/8·|R_d''| in u; measured ≤ 4.3e-8 in α′ over a fine sweep.
            EXPECT_NEAR(table.reducedAlbedo(totalDiffuseReflectance(albedo, eta)), albedo, 1e-6)
                << "η " << eta << " α′ " << albedo;
        }
    }
}

TEST(DipoleTest, ReducedAlbedoMatchesIndependentValues) {
    // R_d values from Python (above) for α′ = 0.1 … 0.999 at η = 1.3; the table must find the
    // α′ back. Interpolation error as in the round trip, ≤ 4.3e-8.
    const ReducedAlbedoTable table(1.3);
    EXPECT_NEAR(table.reducedAlbedo(0.009700612501691705), 0.1, 1e-6);
    EXPECT_NEAR(table.reducedAlbedo(0.07450596239970708), 0.5, 1e-6);
    EXPECT_NEAR(table.reducedAlbedo(0.2991140031023451), 0.9, 1e-6);
    EXPECT_NEAR(table.reducedAlbedo(0.6444973594119497), 0.99, 1e-6);
    EXPECT_NEAR(table.reducedAlbedo(0.8639008246078914), 0.999, 1e-6);
}

TEST(DipoleTest, ReducedAlbedoClampsTheReflectance) {
    const ReducedAlbedoTable table(1.3);
    // R_d ≥ 0.999 is treated as 0.999: α′ < 1, so σa stays positive.
    EXPECT_DOUBLE_EQ(table.reducedAlbedo(1.0), table.reducedAlbedo(0.999));
    EXPECT_DOUBLE_EQ(table.reducedAlbedo(5.0), table.reducedAlbedo(0.999));
    EXPECT_LT(table.reducedAlbedo(0.999), 1.0);
    EXPECT_DOUBLE_EQ(table.reducedAlbedo(-0.5), 0.0);
    EXPECT_DOUBLE_EQ(table.reducedAlbedo(0.0), 0.0);
    // Monotonic: brighter colours need less absorption.
    double previous = -1.0;
    for (double rd = 0.0; rd <= 1.0; rd += 0.01) {
        const double albedo = table.reducedAlbedo(rd);
        EXPECT_GE(albedo, previous) << rd;
        previous = albedo;
    }
}

TEST(DipoleTest, CoefficientsFromReflectanceRecoverTheMeasuredMaterials) {
    // A material's own R_d and ld = 1/σtr must lead back to its σs′ and σa (DESIGN §6.4).
    for (const Material& material : materialLibrary()) {
        if (!measured(material) || material.name == "spectralon") {
            continue;  // Spectralon does not absorb: ld is infinite and R_d = 1 is clamped.
        }
        const DipoleProfile dipole(*material.sigmaSPrime, *material.sigmaA, material.eta);
        const ScatteringCoefficients recovered =
            coefficientsFromReflectance(ReducedAlbedoTable(material.eta), dipole.totalReflectance(),
                                        dipole.diffuseMeanFreePathMm());
        for (int c = 0; c < 3; ++c) {
            // σa = σtr·u/√3 and σs′ ≈ σtr/(√3 u) with u = √(1 − α′) from the table, so their
            // relative error is that of u: the interpolation's ~1e-8 over a small u, 0.005 for
            // cream's red (α′ = 0.99997). Measured ≤ 7.7e-6.
            EXPECT_NEAR(recovered.sigmaSPrime[c] / (*material.sigmaSPrime)[c], 1.0, 1e-4)
                << material.name << " " << kChannel[c];
            EXPECT_NEAR(recovered.sigmaA[c] / (*material.sigmaA)[c], 1.0, 1e-4)
                << material.name << " " << kChannel[c];
        }
    }
}

/// α′ with totalDiffuseReflectance(α′, η) = R_d by bisection on [0, 1] (R_d rises with α′):
/// independent of the table's interpolation.
double bisectReducedAlbedo(double reflectance, double eta) {
    double low = 0.0, high = 1.0;
    for (int i = 0; i < 100; ++i) {
        const double middle = 0.5 * (low + high);
        (totalDiffuseReflectance(middle, eta) < reflectance ? low : high) = middle;
    }
    return 0.5 * (low + high);
}

TEST(DipoleTest, InversionMatchesBisection) {
    for (const double eta : {1.0, 1.3, 1.5, 2.0}) {
        const ReducedAlbedoTable table(eta);
        // The GPU's table: u = √(1 − α′) at R_d = i/4095 · 0.999.
        const std::vector<float> roots = reducedAlbedoRootTable(table, 4096);
        ASSERT_EQ(roots.size(), 4096u);
        for (int i = 0; i <= 1000; ++i) {
            const double reflectance = 0.999 * i / 1000.0;
            const double expected = bisectReducedAlbedo(reflectance, eta);
            // The CPU table: linear in u over 4096 entries, ≤ 4.3e-8 in α′ (above).
            EXPECT_NEAR(table.reducedAlbedo(reflectance), expected, 1e-6)
                << "η " << eta << " R_d " << reflectance;
        }
        for (std::size_t i = 0; i < roots.size(); i += 91) {
            const double reflectance = 0.999 * static_cast<double>(i) / 4095.0;
            // Float storage (6e-8 relative) and the CPU table's interpolation, which at the
            // bright end (u < 0.01, where its entries are 1/4095 apart in u) errs by up to
            // 1.4e-7 in u: 0.2 % of the smallest u (8.6e-5, η = 1, R_d = 0.999), below the 1 %
            // the GPU's coefficients are held to.
            EXPECT_NEAR(roots[i], std::sqrt(1.0 - bisectReducedAlbedo(reflectance, eta)),
                        5e-5 * roots[i] + 2e-7)
                << "η " << eta << " entry " << i;
        }
        EXPECT_FLOAT_EQ(roots.front(), 1.0f);  // R_d = 0: α′ = 0
        EXPECT_GT(roots.back(), 0.0f);         // clamped below α′ = 1, so σa > 0
    }
}

TEST(DipoleTest, BadInputsAreErrors) {
    EXPECT_THROW(DipoleChannel(-1.0, 0.1, 1.3), Error);
    EXPECT_THROW(DipoleChannel(0.0, 0.0, 1.3), Error);
    EXPECT_THROW(ReducedAlbedoTable(1.3, 1), Error);
    EXPECT_THROW(reducedAlbedoRootTable(ReducedAlbedoTable(1.3), 1), Error);
    const ReducedAlbedoTable table(1.3);
    EXPECT_THROW(coefficientsFromReflectance(table, {0.5, 0.5, 0.5}, {1.0, 0.0, 1.0}), Error);
}

}  // namespace
}  // namespace subscan
