#pragma once

#include <array>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace subscan {

/// One term of a diffusion profile R(r) ≈ Σ wᵢ G(vᵢ, r), G(v, r) = exp(−r²/2v) / (2πv), r in mm.
struct Gaussian {
    double varianceMm2 = 0.0;        // vᵢ; 0 means "unblurred" (a delta)
    std::array<double, 3> weight{};  // wᵢ per linear RGB channel
};

/// A sum of Gaussians with variances shared by R, G and B, so one blur per Gaussian serves all
/// three channels. In a cumulative set (Jimenez 2009) the variances grow and pass i blurs the
/// previous pass's result by √(vᵢ − vᵢ₋₁); the weights still belong to G(vᵢ).
struct GaussianSet {
    std::vector<Gaussian> gaussians;
    bool cumulative = false;

    /// Σ wᵢ G(vᵢ, r) per channel (a zero-variance term contributes only at r = 0, as a delta:
    /// it is left out here).
    std::array<double, 3> evaluate(double radiusMm) const;
    /// Σ wᵢ per channel: 1 for a profile normalised to unit energy.
    std::array<double, 3> weightSums() const;
    double largestVarianceMm2() const;
};

/// The terms as `subscan fit-profile --json` and `materials --json` list them:
/// [{"variance_mm2": v, "weight": [R, G, B]}, ...].
nlohmann::json gaussiansJson(const GaussianSet& set);
/// The terms of such a list (throws nlohmann::json's errors when a field is missing).
GaussianSet gaussiansFromJson(const nlohmann::json& terms);

}  // namespace subscan
