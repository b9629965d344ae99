#include "sss/MaterialLibrary.h"

#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"

namespace subscan {

namespace {

/// The 6-Gaussian set stored for a Jensen material by scripts/fit-materials.sh, or an empty set
/// when there is none yet (the material library test then fails, asking for the script).
GaussianSet storedFit(std::string_view material) {
    struct StoredFit {
        std::string_view material;
        std::string_view json;  // `subscan fit-profile --json` output
    };
    static const std::vector<StoredFit> kStoredFits{
#include "sss/JensenGaussians.inc"
    };
    for (const StoredFit& stored : kStoredFits) {
        if (stored.material != material) {
            continue;
        }
        return gaussiansFromJson(nlohmann::json::parse(stored.json).at("gaussians"));
    }
    return {};
}

/// Jensen et al. 2001's measured materials: σs′ and σa in mm⁻¹ and the total diffuse reflectance
/// (DESIGN §6.2), each with a set fitted to its dipole profile.
void appendJensenMaterials(std::vector<Material>& materials) {
    struct Measurement {
        const char* name;
        double eta;
        Rgb sigmaSPrime;
        Rgb sigmaA;
        Rgb rd;
    };
    static constexpr Measurement kMeasurements[] = {
        {"apple", 1.3, {2.29, 2.39, 1.97}, {0.0030, 0.0034, 0.046}, {0.85, 0.84, 0.53}},
        {"chicken1", 1.3, {0.15, 0.21, 0.38}, {0.015, 0.077, 0.19}, {0.31, 0.15, 0.10}},
        {"chicken2", 1.3, {0.19, 0.25, 0.32}, {0.018, 0.088, 0.20}, {0.32, 0.16, 0.10}},
        {"cream", 1.3, {7.38, 5.47, 3.15}, {0.0002, 0.0028, 0.0163}, {0.98, 0.90, 0.73}},
        {"ketchup", 1.3, {0.18, 0.07, 0.03}, {0.061, 0.97, 1.45}, {0.16, 0.01, 0.00}},
        {"marble", 1.5, {2.19, 2.62, 3.00}, {0.0021, 0.0041, 0.0071}, {0.83, 0.79, 0.75}},
        {"potato", 1.3, {0.68, 0.70, 0.55}, {0.0024, 0.0090, 0.12}, {0.77, 0.62, 0.21}},
        {"skimmilk", 1.3, {0.70, 1.22, 1.90}, {0.0014, 0.0025, 0.0142}, {0.81, 0.81, 0.69}},
        {"skin1", 1.3, {0.74, 0.88, 1.01}, {0.032, 0.17, 0.48}, {0.44, 0.22, 0.13}},
        {"skin2", 1.3, {1.09, 1.59, 1.79}, {0.013, 0.070, 0.145}, {0.63, 0.44, 0.34}},
        {"spectralon", 1.3, {11.6, 20.4, 14.9}, {0.0, 0.0, 0.0}, {1.00, 1.00, 1.00}},
        {"wholemilk", 1.3, {2.55, 3.21, 3.77}, {0.0011, 0.0024, 0.014}, {0.91, 0.88, 0.76}},
    };
    for (const Measurement& measured : kMeasurements) {
        materials.push_back(
            {measured.name,
             fmt::format("{}, measured by Jensen et al. 2001; 6 Gaussians fitted to its dipole "
                         "profile",
                         measured.name),
             measured.eta, measured.sigmaSPrime, measured.sigmaA, measured.rd,
             storedFit(measured.name)});
    }
}

std::vector<Material> builtInMaterials() {
    std::vector<Material> materials;
    materials.push_back({"skin-deon",
                         "skin, 6 Gaussians (d'Eon & Luebke 2007, GPU Gems 3 ch. 14)",
                         1.4,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0064, {0.233, 0.455, 0.649}},
                           {0.0484, {0.100, 0.336, 0.344}},
                           {0.187, {0.118, 0.198, 0.0}},
                           {0.567, {0.113, 0.007, 0.007}},
                           {1.99, {0.358, 0.004, 0.0}},
                           {7.41, {0.078, 0.0, 0.0}}},
                          false}});
    materials.push_back({"skin-jimenez",
                         "skin, 4 cumulative Gaussians (Jimenez et al. 2009)",
                         1.4,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0, {0.2405, 0.4474, 0.6158}},
                           {0.0516500, {0.1159, 0.3662, 0.3439}},
                           {0.2719281, {0.1836, 0.1864, 0.0}},
                           {2.0062639, {0.4600, 0.0, 0.0403}}},
                          true}});
    materials.push_back({"marble-jimenez",
                         "marble, 4 cumulative Gaussians (Jimenez et al. 2009)",
                         1.5,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0362209, {0.0545, 0.1245, 0.2177}},
                           {0.1144506, {0.2437, 0.2435, 0.1890}},
                           {0.4555844, {0.3105, 0.3158, 0.3742}},
                           {3.4833196, {0.3913, 0.3161, 0.2190}}},
                          true}});
    appendJensenMaterials(materials);
    return materials;
}

}  // namespace

const std::vector<Material>& materialLibrary() {
    static const std::vector<Material> materials = builtInMaterials();
    return materials;
}

const Material& findMaterial(std::string_view name) {
    std::string known;
    for (const Material& material : materialLibrary()) {
        if (material.name == name) {
            return material;
        }
        known += (known.empty() ? "" : ", ") + material.name;
    }
    throw Error(fmt::format("there is no material '{}'; the materials are {}", name, known));
}

}  // namespace subscan

namespace subscan {

const Material& measuredMaterial(std::string_view name) {
    const Material& material = findMaterial(name);
    if (material.sigmaSPrime && material.sigmaA) {
        return material;
    }
    std::string measured;
    for (const Material& candidate : materialLibrary()) {
        if (candidate.sigmaSPrime && candidate.sigmaA) {
            measured += (measured.empty() ? "" : ", ") + candidate.name;
        }
    }
    throw Error(fmt::format(
        "the material '{}' is a Gaussian set without measured σs′ and σa, so single scattering "
        "cannot take its coefficients; choose one of {} or coefficients 'color'",
        name, measured));
}

nlohmann::json materialJson(const Material& material) {
    const auto optionalRgb = [](const std::optional<Rgb>& value) {
        return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
    };
    return {
        {"name", material.name},
        {"description", material.description},
        {"eta", material.eta},
        {"sigma_s_prime", optionalRgb(material.sigmaSPrime)},
        {"sigma_a", optionalRgb(material.sigmaA)},
        {"rd", optionalRgb(material.rd)},
        {"cumulative", material.gaussians.cumulative},
        {"gaussians", gaussiansJson(material.gaussians)},
    };
}

}  // namespace subscan
