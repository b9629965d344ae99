#include "sss/Dipole.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

double diffuseFresnelReflectance(double eta) {
    if (!(eta >= 1.0)) {
        throw Error(fmt::format(
            "the relative index of refraction must be at least 1 for the diffuse Fresnel "
            "reflectance fit, not {}",
            eta));
    }
    return -1.4399 / (eta * eta) + 0.7099 / eta + 0.6681 + 0.0636 * eta;
}

double boundaryReflectionParameter(double eta) {
    const double fresnel = diffuseFresnelReflectance(eta);
    return (1.0 + fresnel) / (1.0 - fresnel);
}

double totalDiffuseReflectance(double reducedAlbedo, double eta) {
    const double a = boundaryReflectionParameter(eta);
    // √(3(1 − α′)), not √(3·1 − α′): σtr·z_r, the optical depth of the real source.
    const double sourceDepth = std::sqrt(3.0 * (1.0 - reducedAlbedo));
    return 0.5 * reducedAlbedo * (1.0 + std::exp(-4.0 / 3.0 * a * sourceDepth)) *
           std::exp(-sourceDepth);
}

DipoleChannel::DipoleChannel(double sigmaSPrime, double sigmaA, double eta) : eta_(eta) {
    const double extinction = sigmaSPrime + sigmaA;
    if (!(sigmaSPrime >= 0.0 && sigmaA >= 0.0 && extinction > 0.0) || !std::isfinite(extinction)) {
        throw Error(fmt::format(
            "the dipole needs finite σs′ ≥ 0 and σa ≥ 0 with a positive sum, not σs′ = {} and "
            "σa = {} mm⁻¹",
            sigmaSPrime, sigmaA));
    }
    reducedAlbedo_ = sigmaSPrime / extinction;
    effectiveExtinction_ = std::sqrt(3.0 * sigmaA * extinction);
    realSourceDepth_ = 1.0 / extinction;
    virtualSourceHeight_ = realSourceDepth_ * (1.0 + 4.0 / 3.0 * boundaryReflectionParameter(eta));
}

double DipoleChannel::reflectance(double radiusMm) const {
    auto source = [&](double depth) {
        const double distance = std::sqrt(radiusMm * radiusMm + depth * depth);
        return depth * (effectiveExtinction_ * distance + 1.0) *
               std::exp(-effectiveExtinction_ * distance) / (distance * distance * distance);
    };
    return reducedAlbedo_ / (4.0 * std::numbers::pi) *
           (source(realSourceDepth_) + source(virtualSourceHeight_));
}

double DipoleChannel::totalReflectance() const {
    return totalDiffuseReflectance(reducedAlbedo_, eta_);
}

double DipoleChannel::diffuseMeanFreePathMm() const {
    return effectiveExtinction_ > 0.0 ? 1.0 / effectiveExtinction_
                                      : std::numeric_limits<double>::infinity();
}

DipoleProfile::DipoleProfile(const Rgb& sigmaSPrime, const Rgb& sigmaA, double eta)
    : channels_{DipoleChannel(sigmaSPrime[0], sigmaA[0], eta),
                DipoleChannel(sigmaSPrime[1], sigmaA[1], eta),
                DipoleChannel(sigmaSPrime[2], sigmaA[2], eta)} {}

Rgb DipoleProfile::reflectance(double radiusMm) const {
    return {channels_[0].reflectance(radiusMm), channels_[1].reflectance(radiusMm),
            channels_[2].reflectance(radiusMm)};
}

Rgb DipoleProfile::totalReflectance() const {
    return {channels_[0].totalReflectance(), channels_[1].totalReflectance(),
            channels_[2].totalReflectance()};
}

Rgb DipoleProfile::diffuseMeanFreePathMm() const {
    return {channels_[0].diffuseMeanFreePathMm(), channels_[1].diffuseMeanFreePathMm(),
            channels_[2].diffuseMeanFreePathMm()};
}

ReducedAlbedoTable::ReducedAlbedoTable(double eta, std::size_t entries) : eta_(eta) {
    if (entries < 2) {
        throw Error("the reduced albedo table needs at least 2 entries");
    }
    reflectanceByRoot_.resize(entries);
    for (std::size_t i = 0; i < entries; ++i) {
        const double root = static_cast<double>(i) / static_cast<double>(entries - 1);
        reflectanceByRoot_[i] = totalDiffuseReflectance(1.0 - root * root, eta);
    }
}

double ReducedAlbedoTable::reducedAlbedo(double totalReflectance) const {
    const double target = std::clamp(totalReflectance, 0.0, kMaxReflectance);
    // The first entry not above the target. The table falls from R_d = 1 at u = 0 to R_d = 0 at
    // u = 1, so for a target in [0, 0.999] that entry exists and is not the first.
    const auto above = std::partition_point(reflectanceByRoot_.begin(), reflectanceByRoot_.end(),
                                            [&](double value) { return value > target; });
    const std::size_t upper = static_cast<std::size_t>(above - reflectanceByRoot_.begin());
    const double brighter = reflectanceByRoot_[upper - 1];
    const double darker = reflectanceByRoot_[upper];
    const double fraction = (brighter - target) / (brighter - darker);
    const double step = 1.0 / static_cast<double>(reflectanceByRoot_.size() - 1);
    const double root = (static_cast<double>(upper - 1) + fraction) * step;
    return 1.0 - root * root;
}

std::vector<float> reducedAlbedoRootTable(const ReducedAlbedoTable& table, std::size_t entries) {
    if (entries < 2) {
        throw Error("the reduced albedo table needs at least 2 entries");
    }
    std::vector<float> roots(entries);
    for (std::size_t i = 0; i < entries; ++i) {
        const double reflectance = ReducedAlbedoTable::kMaxReflectance * static_cast<double>(i) /
                                   static_cast<double>(entries - 1);
        roots[i] = static_cast<float>(std::sqrt(1.0 - table.reducedAlbedo(reflectance)));
    }
    return roots;
}

ScatteringCoefficients coefficientsFromReflectance(const ReducedAlbedoTable& table,
                                                   const Rgb& totalReflectance,
                                                   const Rgb& diffuseMeanFreePathMm) {
    ScatteringCoefficients coefficients;
    for (int c = 0; c < 3; ++c) {
        const double meanFreePath = diffuseMeanFreePathMm[c];
        if (!(meanFreePath > 0.0) || !std::isfinite(meanFreePath)) {
            throw Error(fmt::format(
                "the diffuse mean free path must be a positive number of millimetres, not {}",
                meanFreePath));
        }
        const double albedo = table.reducedAlbedo(totalReflectance[c]);
        const double extinction = (1.0 / meanFreePath) / std::sqrt(3.0 * (1.0 - albedo));
        coefficients.sigmaSPrime[c] = albedo * extinction;
        coefficients.sigmaA[c] = extinction - coefficients.sigmaSPrime[c];
    }
    return coefficients;
}

}  // namespace subscan
