#include "sss/SingleScattering.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

namespace subscan {

namespace {

/// n_j: how many of `samples` samples channel j draws (sample k belongs to channel k mod 3).
int channelSamples(int samples, int channel) {
    return (samples + 2 - channel) / 3;
}

}  // namespace

double refractedCosine(double cosine, double eta) {
    const double sine2 = std::max(0.0, 1.0 - cosine * cosine) / (eta * eta);
    return std::sqrt(std::max(0.0, 1.0 - sine2));
}

glm::dvec3 refractedDirection(const glm::dvec3& direction, const glm::dvec3& normal, double eta) {
    const double cosine = glm::dot(direction, normal);
    return (direction - cosine * normal) / eta + refractedCosine(cosine, eta) * normal;
}

double fresnelTransmittance(double cosine, double eta) {
    const double cosOutside = std::clamp(std::abs(cosine), 0.0, 1.0);
    const double cosInside = refractedCosine(cosOutside, eta);
    const double perpendicular = (cosOutside - eta * cosInside) / (cosOutside + eta * cosInside);
    const double parallel = (eta * cosOutside - cosInside) / (eta * cosOutside + cosInside);
    return 1.0 - 0.5 * (perpendicular * perpendicular + parallel * parallel);
}

double henyeyGreenstein(double cosine, double g) {
    const double denominator = 1.0 + g * g - 2.0 * g * cosine;
    return (1.0 - g * g) / (4.0 * std::numbers::pi * denominator * std::sqrt(denominator));
}

double singleScatteringGeometry(const glm::dvec3& toLight, const glm::dvec3& entryNormal,
                                const glm::dvec3& toEye, const glm::dvec3& exitNormal, double eta,
                                double g) {
    const double cosIn = std::abs(glm::dot(entryNormal, toLight));
    const double cosOut = glm::dot(exitNormal, toEye);
    if (!(cosIn > 0.0) || !(cosOut > 0.0)) {
        return 0.0;
    }
    const glm::dvec3 orientedEntry =
        glm::dot(entryNormal, toLight) >= 0.0 ? entryNormal : -entryNormal;
    const glm::dvec3 lightInside = refractedDirection(toLight, orientedEntry, eta);
    const glm::dvec3 eyeInside = refractedDirection(toEye, exitNormal, eta);
    const double phase = henyeyGreenstein(-glm::dot(lightInside, eyeInside), g);
    const double compression = cosIn / refractedCosine(cosIn, eta);
    return phase * fresnelTransmittance(cosIn, eta) * fresnelTransmittance(cosOut, eta) /
           (eta * eta) * compression;
}

double semiInfiniteSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                                const glm::dvec3& toLight, const glm::dvec3& toEye,
                                double irradiance) {
    const double cosIn = glm::dot(normal, toLight);
    const double cosOut = glm::dot(normal, toEye);
    if (!(cosIn > 0.0) || !(cosOut > 0.0)) {
        return 0.0;
    }
    const double geometry =
        singleScatteringGeometry(toLight, normal, toEye, normal, medium.eta, medium.g);
    // The integral of σs e^(−σt s (1 + cos θo′/cos θi′)) over s is α cos θi′ / (cos θi′ + cos θo′).
    const double cosInInside = refractedCosine(cosIn, medium.eta);
    const double cosOutInside = refractedCosine(cosOut, medium.eta);
    return medium.albedo() * geometry * irradiance * cosInInside / (cosInInside + cosOutInside);
}

double frontLitSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                            const glm::dvec3& toLight, const glm::dvec3& toEye, double irradiance,
                            double thickness) {
    const double a = 1.0 / refractedCosine(glm::dot(normal, toLight), medium.eta);
    const double b = 1.0 / refractedCosine(glm::dot(normal, toEye), medium.eta);
    return semiInfiniteSlabRadiance(medium, normal, toLight, toEye, irradiance) *
           (1.0 - std::exp(-medium.sigmaT() * thickness * (a + b)));
}

double backLitSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                           const glm::dvec3& toLight, const glm::dvec3& toEye, double irradiance,
                           double thickness) {
    const double cosIn = -glm::dot(normal, toLight);
    const double cosOut = glm::dot(normal, toEye);
    if (!(cosIn > 0.0) || !(cosOut > 0.0)) {
        return 0.0;
    }
    const double geometry =
        singleScatteringGeometry(toLight, -normal, toEye, normal, medium.eta, medium.g);
    const double a = 1.0 / refractedCosine(cosIn, medium.eta);
    const double b = 1.0 / refractedCosine(cosOut, medium.eta);
    const double sigmaT = medium.sigmaT();
    // ∫₀^{d b} σs e^(−σt a (d − s/b)) e^(−σt s) ds, with its limit where a = b.
    const double path =
        std::abs(a - b) < 1e-9
            ? b * sigmaT * thickness * std::exp(-sigmaT * b * thickness)
            : b * (std::exp(-sigmaT * b * thickness) - std::exp(-sigmaT * a * thickness)) / (a - b);
    return medium.albedo() * geometry * irradiance * path;
}

double singleScatteringSampleDistance(const Rgb& sigmaT, int samples, int index,
                                      const Rgb& offsets) {
    const int channel = index % 3;
    const double xi = (index / 3 + offsets[channel]) / channelSamples(samples, channel);
    return -std::log1p(-xi) / sigmaT[channel];
}

Rgb estimateSingleScattering(const Rgb& sigmaS, const Rgb& sigmaT, int samples, const Rgb& offsets,
                             const std::function<LightAtSample(double s)>& lightAt) {
    Rgb radiance{};
    for (int k = 0; k < samples; ++k) {
        const double s = singleScatteringSampleDistance(sigmaT, samples, k, offsets);
        double density = 0.0;  // Σ_j n_j σt_j e^(−σt_j s)
        for (int j = 0; j < 3; ++j) {
            density += channelSamples(samples, j) * sigmaT[j] * std::exp(-sigmaT[j] * s);
        }
        const LightAtSample light = lightAt(s);
        if (light.weight == 0.0) {
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            radiance[c] +=
                sigmaS[c] * light.weight * std::exp(-sigmaT[c] * (s + light.lightPath)) / density;
        }
    }
    return radiance;
}

}  // namespace subscan
