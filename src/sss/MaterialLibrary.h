#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "sss/GaussianSet.h"

namespace subscan {

using Rgb = std::array<double, 3>;

/// A translucent material: its measured optical properties where they exist (Jensen et al.
/// 2001, mm⁻¹) and the Gaussian set the screen-space blur uses.
struct Material {
    std::string name;                // e.g. "marble-jimenez", "skin1"
    std::string description;         // where the numbers come from
    double eta = 1.3;                // relative index of refraction
    std::optional<Rgb> sigmaSPrime;  // reduced scattering coefficient σs′, mm⁻¹
    std::optional<Rgb> sigmaA;       // absorption coefficient σa, mm⁻¹
    std::optional<Rgb> rd;           // total diffuse reflectance as measured (Jensen's table)
    GaussianSet gaussians;
};

/// Every built-in material, in a stable order.
const std::vector<Material>& materialLibrary();

/// The material called `name`; throws Error naming the known materials when there is none.
const Material& findMaterial(std::string_view name);

/// The material called `name` when it has measured σs′ and σa (single scattering needs them);
/// throws Error naming the materials that do when it has none.
const Material& measuredMaterial(std::string_view name);

/// One entry of `subscan materials --json` (missing measurements are null).
nlohmann::json materialJson(const Material& material);

}  // namespace subscan
