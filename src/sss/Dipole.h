#pragma once

#include <cstddef>
#include <vector>

#include "sss/MaterialLibrary.h"

namespace subscan {

/// Fresnel diffuse reflectance F_dr(η), the polynomial fit for η ≥ 1 that Jensen et al. 2001
/// use (from Egan & Hilgeman 1973). Throws Error for η < 1, where that fit does not hold.
double diffuseFresnelReflectance(double eta);

/// A = (1 + F_dr) / (1 − F_dr): how much light the boundary reflects back inside.
double boundaryReflectionParameter(double eta);

/// Total diffuse reflectance of a semi-infinite medium, the dipole's R_d(r) integrated over the
/// plane: R_d = (α′/2)(1 + e^{−(4/3)A√(3(1−α′))}) e^{−√(3(1−α′))}, α′ = σs′/σt′ (DESIGN §6.2).
double totalDiffuseReflectance(double reducedAlbedo, double eta);

/// Jensen et al. 2001's dipole diffusion profile for one colour channel; lengths in mm.
class DipoleChannel {
  public:
    /// σs′ and σa in mm⁻¹ (σs′ + σa > 0, σa ≥ 0).
    DipoleChannel(double sigmaSPrime, double sigmaA, double eta);

    /// R_d(r) in mm⁻²: the light leaving the surface at distance r from where a unit flux
    /// entered.
    double reflectance(double radiusMm) const;
    /// The closed-form ∫R_d(r) 2πr dr.
    double totalReflectance() const;
    double reducedAlbedo() const { return reducedAlbedo_; }
    /// 1/σtr in mm, the length scale of the profile's tail (infinite when σa = 0).
    double diffuseMeanFreePathMm() const;

  private:
    double reducedAlbedo_;        // α′ = σs′/σt′
    double effectiveExtinction_;  // σtr = √(3σaσt′), mm⁻¹
    double realSourceDepth_;      // z_r = 1/σt′, mm
    double virtualSourceHeight_;  // z_v = z_r(1 + 4A/3), mm
    double eta_;
};

/// The dipole of all three channels, e.g. of a Jensen material.
class DipoleProfile {
  public:
    DipoleProfile(const Rgb& sigmaSPrime, const Rgb& sigmaA, double eta);

    Rgb reflectance(double radiusMm) const;
    Rgb totalReflectance() const;
    Rgb diffuseMeanFreePathMm() const;
    const DipoleChannel& channel(int c) const { return channels_[c]; }

  private:
    std::array<DipoleChannel, 3> channels_;
};

/// The R_d(α′) curve of one η, tabulated once and inverted by interpolation (DESIGN §6.4):
/// which reduced albedo makes a medium as bright as a scanned colour.
class ReducedAlbedoTable {
  public:
    /// Brighter colours are clamped to this: R_d → 1 needs α′ → 1, a medium that never absorbs.
    static constexpr double kMaxReflectance = 0.999;

    explicit ReducedAlbedoTable(double eta, std::size_t entries = 4096);

    /// α′ with totalDiffuseReflectance(α′, η) = R_d, R_d clamped to [0, kMaxReflectance].
    double reducedAlbedo(double totalReflectance) const;
    double eta() const { return eta_; }

  private:
    // The table is uniform in u = √(1 − α′) rather than in α′: R_d has an infinite slope in α′
    // at α′ = 1 (through √(1 − α′)) but is smooth in u, so linear interpolation stays accurate
    // right up to the bright end where scanned colours often are.
    double eta_;
    std::vector<double> reflectanceByRoot_;  // R_d at u = i/(entries − 1), falling from 1 to 0
};

/// The table the GPU inverts R_d with (SingleScattering.comp): u = √(1 − α′) at
/// R_d = i/(entries − 1) · kMaxReflectance, for linear interpolation in R_d. u rather than α′
/// because σa = σtr u/√3 and σs′ = σtr (1 − u²)/(√3 u): both follow u's interpolation error
/// relatively, where α′ near 1 would lose σa to rounding.
std::vector<float> reducedAlbedoRootTable(const ReducedAlbedoTable& table, std::size_t entries);

/// σs′ and σa in mm⁻¹.
struct ScatteringCoefficients {
    Rgb sigmaSPrime{};
    Rgb sigmaA{};
};

/// DESIGN §6.4: the coefficients of a medium with total diffuse reflectance R_d and diffuse mean
/// free path ld (mm, > 0) per channel: α′ from the table, σtr = 1/ld, σt′ = σtr/√(3(1−α′)),
/// σs′ = α′σt′, σa = σt′ − σs′.
ScatteringCoefficients coefficientsFromReflectance(const ReducedAlbedoTable& table,
                                                   const Rgb& totalReflectance,
                                                   const Rgb& diffuseMeanFreePathMm);

}  // namespace subscan
