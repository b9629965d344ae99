#pragma once

#include <functional>

#include <glm/vec3.hpp>

#include "sss/MaterialLibrary.h"

namespace subscan {

// Single scattering under a smooth dielectric boundary (DESIGN.md §6.3). Directions are unit
// vectors pointing away from the surface (towards the light, towards the eye); the normal points
// out of the medium. Lengths are in any one unit, coefficients in its inverse.

/// cos θ′ of the direction refracted into a medium of relative index `eta` ≥ 1 from one that
/// meets the boundary at cos θ (Snell: sin θ = η sin θ′).
double refractedCosine(double cosine, double eta);

/// The refracted direction for `direction` (cos θ = n·ω > 0), still pointing out of the surface:
/// ω′ = (ω − cos θ n)/η + cos θ′ n.
glm::dvec3 refractedDirection(const glm::dvec3& direction, const glm::dvec3& normal, double eta);

/// 1 − F_r: the unpolarised Fresnel transmittance of the boundary at cos θ (the same from either
/// side by reciprocity when θ is taken outside).
double fresnelTransmittance(double cosine, double eta);

/// The Henyey-Greenstein phase function (per steradian) of the cosine between the propagation
/// directions before and after scattering.
double henyeyGreenstein(double cosine, double g);

/// One colour channel of a homogeneous medium: the unreduced σs (= σs′/(1 − g)) and σa.
struct ScatteringMedium {
    double sigmaS = 0.0;
    double sigmaA = 0.0;
    double eta = 1.3;
    double g = 0.0;
    double sigmaT() const { return sigmaS + sigmaA; }
    double albedo() const { return sigmaS / sigmaT(); }
};

/// The channel-independent factors of the single-scattering integrand for a light entering the
/// boundary at cos θi (with entry normal n_i) and leaving at cos θo:
/// p(μ) T_i T_o / η² · cos θi / cos θi′, μ = −ω_i′·ω_o′. Multiply by E = πc and σs e^(−σt(s +
/// s_i′)).
double singleScatteringGeometry(const glm::dvec3& toLight, const glm::dvec3& entryNormal,
                                const glm::dvec3& toEye, const glm::dvec3& exitNormal, double eta,
                                double g);

/// Closed forms of a flat homogeneous slab with normal `normal`, lit by irradiance `irradiance`
/// (perpendicular to the beam, E = πc) from `toLight`, seen from `toEye` (DESIGN.md §6.3).
/// Semi-infinite, lit from the eye's side: α T_i T_o p E cos θi / (η²(cos θi′ + cos θo′)).
double semiInfiniteSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                                const glm::dvec3& toLight, const glm::dvec3& toEye,
                                double irradiance);
/// Thickness d, lit from the eye's side: the semi-infinite value × [1 − e^(−σt d (1/cos θi′ +
/// 1/cos θo′))].
double frontLitSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                            const glm::dvec3& toLight, const glm::dvec3& toEye, double irradiance,
                            double thickness);
/// Thickness d, lit through the far face (whose outward normal is −normal; `toLight` points
/// away from that face, n·ω_i < 0).
double backLitSlabRadiance(const ScatteringMedium& medium, const glm::dvec3& normal,
                           const glm::dvec3& toLight, const glm::dvec3& toEye, double irradiance,
                           double thickness);

/// What one sample along the refracted view ray sees of one light: the channel-independent
/// geometry factor (singleScatteringGeometry × E) and the refracted path s_i′ from the sample
/// back to where that light entered. A weight of 0 means no light reaches the sample.
struct LightAtSample {
    double weight = 0.0;
    double lightPath = 0.0;
};

/// The estimator the single-scattering pass uses, in double precision (DESIGN.md §6.3):
///   L_c = Σ_k σs_c w(s_k) e^(−σt_c (s_k + s_i′(s_k))) / Σ_j n_j σt_j e^(−σt_j s_k),
/// with n_j of the `samples` samples drawn from channel j's free-path density σt_j e^(−σt_j s)
/// (sample k from channel k mod 3, stratified: ξ = (i + offset_j)/n_j for its i-th). This is
/// the balance-heuristic combination of the three channels' densities: unbiased for any
/// offsets drawn uniformly from [0, 1), and a midpoint rule with offsets 1/2 (the GPU's). Each
/// channel's weight e^(−σt_c s)/pdf stays bounded, which one shared density would not give a
/// coloured medium.
Rgb estimateSingleScattering(const Rgb& sigmaS, const Rgb& sigmaT, int samples, const Rgb& offsets,
                             const std::function<LightAtSample(double s)>& lightAt);

/// Where sample `index` of `samples` lies along the refracted view ray (the estimator's rule
/// above).
double singleScatteringSampleDistance(const Rgb& sigmaT, int samples, int index,
                                      const Rgb& offsets);

}  // namespace subscan
