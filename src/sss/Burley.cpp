#include "sss/Burley.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

double burleySearchlightScaling(double albedo) {
    return 1.9 - albedo + 3.5 * (albedo - 0.8) * (albedo - 0.8);
}

BurleyChannel::BurleyChannel(double albedo, double diffuseMeanFreePathMm) : albedo_(albedo) {
    if (!(albedo >= 0.0 && albedo <= 1.0)) {
        throw Error(fmt::format("Burley's profile needs an albedo in [0, 1], not {}", albedo));
    }
    if (!(diffuseMeanFreePathMm > 0.0) || !std::isfinite(diffuseMeanFreePathMm)) {
        throw Error(fmt::format(
            "Burley's profile needs a positive, finite diffuse mean free path, not {} mm",
            diffuseMeanFreePathMm));
    }
    shape_ = burleySearchlightScaling(albedo) / diffuseMeanFreePathMm;
}

double BurleyChannel::reflectance(double radiusMm) const {
    return albedo_ * shape_ * (std::exp(-shape_ * radiusMm) + std::exp(-shape_ * radiusMm / 3.0)) /
           (8.0 * std::numbers::pi * radiusMm);
}

BurleyProfile::BurleyProfile(const Rgb& albedo, const Rgb& diffuseMeanFreePathMm)
    : channels_{BurleyChannel(albedo[0], diffuseMeanFreePathMm[0]),
                BurleyChannel(albedo[1], diffuseMeanFreePathMm[1]),
                BurleyChannel(albedo[2], diffuseMeanFreePathMm[2])} {}

Rgb BurleyProfile::reflectance(double radiusMm) const {
    return {channels_[0].reflectance(radiusMm), channels_[1].reflectance(radiusMm),
            channels_[2].reflectance(radiusMm)};
}

}  // namespace subscan
