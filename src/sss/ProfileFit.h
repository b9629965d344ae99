#pragma once

#include <functional>

#include "sss/GaussianSet.h"
#include "sss/MaterialLibrary.h"

namespace subscan {

/// A radially symmetric diffusion profile per channel: r in mm (> 0) ↦ R(r) in mm⁻², finite and
/// non-negative. Its energy ∫R(r) 2πr dr must lie between 1e-6 mm and 1e6 mm from the centre.
using RadialProfile = std::function<Rgb(double radiusMm)>;

/// The most Gaussians a fit may use. Each costs the renderer two blur passes, and 8 already fit
/// every Jensen dipole within fit_error 0.003.
inline constexpr int kMaxFittedGaussians = 12;

/// ∫R(r) 2πr dr per channel, by the quadrature the fit uses (trapezoids in ln r, which suits
/// profiles peaked at 0 with long tails).
Rgb profileEnergy(const RadialProfile& profile);

/// How well a Gaussian set matches a profile, both normalised to unit energy per channel.
struct FitQuality {
    /// √(∫(F − R)² r dr / ∫R² r dr) over 0 ≤ r ≤ rMaxMm per channel.
    Rgb fitError{};
    /// The radius holding 99.9 % of the energy of the widest channel, mm.
    double rMaxMm = 0.0;
};

struct ProfileFit {
    /// Sorted by variance; weights ≥ 0 summing to 1 per channel; no zero variance.
    GaussianSet gaussians;
    FitQuality quality;
};

/// Fits `gaussianCount` (1..kMaxFittedGaussians) Gaussians with variances shared by R, G and B to
/// the profile normalised to unit energy per channel: least squares on the 2-D integral,
/// minimising Σ_c ∫(F_c − R_c)² r dr / ∫R_c² r dr over the weights (≥ 0, summing to 1 per
/// channel) and the variances. Each channel is weighted by its own ∫R² r dr so that a wide
/// channel, whose normalised profile is low, is fitted as well as a narrow one; unweighted, the
/// narrow channels dominate and e.g. ketchup's red is left at fit_error 0.14 with 4 Gaussians.
/// Deterministic: the same profile gives the same set.
///
/// A profile singular at the centre, like Burley's (R ∝ 1/r), has a ∫R² r dr that diverges
/// logarithmically there; its fit is over r ≥ 10⁻³ × the narrowest channel's 1 %-energy radius
/// and spends Gaussians with tiny variances on the singularity.
ProfileFit fitGaussians(const RadialProfile& profile, int gaussianCount);

/// `subscan fit-profile --json`: the material, the Gaussians, fit_error and r_max_mm.
nlohmann::json profileFitJson(const Material& material, const ProfileFit& fit);

/// The quality of `set` (weights per channel summing to 1) against the normalised profile.
FitQuality measureFit(const RadialProfile& profile, const GaussianSet& set);

enum class ProfileModel { Dipole, Burley };

/// The diffusion profile of a material with measured σs′ and σa: Jensen's dipole, or Burley's
/// normalized diffusion with A = the dipole's total diffuse reflectance and ld = 1/σtr (so both
/// describe the same medium). Throws Error for materials without σs′ and σa, and for Burley when
/// a channel does not absorb (σa = 0 makes ld infinite).
RadialProfile diffusionProfile(const Material& material, ProfileModel model);

}  // namespace subscan
