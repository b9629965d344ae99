#pragma once

#include "sss/MaterialLibrary.h"

namespace subscan {

/// Burley's normalized diffusion profile (Burley 2015; Christensen & Burley 2015) for one
/// channel: R(r) = A·s·(e^{−sr} + e^{−sr/3}) / (8πr), r in mm, R in mm⁻². It integrates to
/// ∫R(r) 2πr dr = A, the surface albedo.
///
/// The shape parameter is s = S(A)/ld with ld the diffuse mean free path (1/σtr, mm) and
/// S(A) = 1.9 − A + 3.5(A − 0.8)², Christensen & Burley's fit of the searchlight configuration
/// (light entering at one point, as in the dipole's R_d(r)) parameterised by ld.
class BurleyChannel {
  public:
    /// A in [0, 1]; ld in mm, positive and finite.
    BurleyChannel(double albedo, double diffuseMeanFreePathMm);

    double reflectance(double radiusMm) const;
    double albedo() const { return albedo_; }
    /// s, mm⁻¹.
    double shape() const { return shape_; }

  private:
    double albedo_;
    double shape_;
};

/// S(A) of the searchlight configuration with ld as the length scale.
double burleySearchlightScaling(double albedo);

/// The three channels, e.g. of a Jensen material with A its total diffuse reflectance and ld
/// its 1/σtr.
class BurleyProfile {
  public:
    BurleyProfile(const Rgb& albedo, const Rgb& diffuseMeanFreePathMm);

    Rgb reflectance(double radiusMm) const;
    const BurleyChannel& channel(int c) const { return channels_[c]; }

  private:
    std::array<BurleyChannel, 3> channels_;
};

}  // namespace subscan
