#include "render/ScatteringSettings.h"

#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "render/SettingsJson.h"
#include "sss/MaterialLibrary.h"

namespace subscan {

namespace {

constexpr std::pair<ScatteringMethod, std::string_view> kMethods[] = {
    {ScatteringMethod::Gaussian, "gaussian"},
    {ScatteringMethod::Single, "single"},
    {ScatteringMethod::Both, "both"},
};
constexpr std::pair<CoefficientSource, std::string_view> kSources[] = {
    {CoefficientSource::Material, "material"},
    {CoefficientSource::Color, "color"},
};
constexpr std::pair<LightPath, std::string_view> kLightPaths[] = {
    {LightPath::Screen, "screen"},
    {LightPath::LightMap, "light_map"},
};
constexpr std::pair<AlbedoPlacement, std::string_view> kPlacements[] = {
    {AlbedoPlacement::PreScatter, "pre"},
    {AlbedoPlacement::PostScatter, "post"},
    {AlbedoPlacement::Split, "split"},
};
constexpr std::pair<SceneUnit, std::string_view> kUnits[] = {
    {SceneUnit::Millimetre, "mm"},
    {SceneUnit::Centimetre, "cm"},
    {SceneUnit::Metre, "m"},
    {SceneUnit::Inch, "in"},
};

}  // namespace

double millimetresPerUnit(SceneUnit unit) {
    switch (unit) {
        case SceneUnit::Millimetre:
            return 1.0;
        case SceneUnit::Centimetre:
            return 10.0;
        case SceneUnit::Metre:
            return 1000.0;
        case SceneUnit::Inch:
            return 25.4;
    }
    return 1.0;
}

double scatteringEta(const ScatteringSettings& settings) {
    return settings.eta ? *settings.eta : findMaterial(settings.material).eta;
}

std::string toString(ScatteringMethod method) {
    return nameOf(kMethods, method);
}
ScatteringMethod parseScatteringMethod(std::string_view text) {
    return parseName(kMethods, text, "scattering method");
}
std::string toString(LightPath path) {
    return nameOf(kLightPaths, path);
}
LightPath parseLightPath(std::string_view text) {
    return parseName(kLightPaths, text, "light path");
}
std::string toString(CoefficientSource source) {
    return nameOf(kSources, source);
}
CoefficientSource parseCoefficientSource(std::string_view text) {
    return parseName(kSources, text, "coefficient source");
}
std::string toString(AlbedoPlacement placement) {
    return nameOf(kPlacements, placement);
}
AlbedoPlacement parseAlbedoPlacement(std::string_view text) {
    return parseName(kPlacements, text, "albedo placement");
}
std::string toString(SceneUnit unit) {
    return nameOf(kUnits, unit);
}
SceneUnit parseSceneUnit(std::string_view text) {
    return parseName(kUnits, text, "unit");
}

void to_json(nlohmann::json& json, const ScatteringSettings& settings) {
    json = {
        {"method", toString(settings.method)},
        {"material", settings.material},
        {"unit", toString(settings.unit)},
        {"scale", settings.scale},
        {"albedo", toString(settings.albedo)},
        {"max_taps", settings.maxTaps},
        {"coefficients", toString(settings.coefficients)},
        {"mean_free_path_mm", toJson(settings.meanFreePathMm)},
        {"eta", settings.eta ? nlohmann::json(*settings.eta) : nlohmann::json(nullptr)},
        {"phase_g", settings.phaseG},
        {"single_samples", settings.singleSamples},
        {"light_path", toString(settings.lightPath)},
        {"transmission", settings.transmission},
    };
}

std::optional<std::string> scaleProblem(float scale) {
    if (scale > 0.0f && scale <= 1000.0f) {
        return std::nullopt;
    }
    return "is outside 0..1000 (exclusive of 0)";
}

std::optional<std::string> meanFreePathProblem(const glm::vec3& millimetres) {
    for (int c = 0; c < 3; ++c) {
        if (!(millimetres[c] > 0.0f) || !std::isfinite(millimetres[c])) {
            return fmt::format("must be positive millimetres in every channel, not {}",
                               millimetres[c]);
        }
    }
    return std::nullopt;
}

std::optional<std::string> etaProblem(float eta) {
    if (eta >= 1.0f && eta <= 3.0f) {
        return std::nullopt;
    }
    return "is outside 1..3 (the relative index of refraction of a medium denser than air)";
}

std::optional<std::string> phaseGProblem(float g) {
    if (std::abs(g) < 1.0f) {
        return std::nullopt;
    }
    return "must lie strictly between -1 and 1 (Henyey-Greenstein)";
}

std::optional<std::string> singleSamplesProblem(int samples) {
    if (samples >= 1 && samples <= 64) {
        return std::nullopt;
    }
    return "is outside 1..64";
}

void checkScatteringSettings(const ScatteringSettings& settings) {
    // Named as the settings file names them: the key, and where it is one number its value.
    const auto refuse = [](const std::optional<std::string>& problem, const std::string& named) {
        if (problem) {
            throw Error(fmt::format("the setting {} {}", named, *problem));
        }
    };
    refuse(meanFreePathProblem(settings.meanFreePathMm), "'mean_free_path_mm'");
    if (settings.eta) {
        refuse(etaProblem(*settings.eta), fmt::format("'eta' = {}", *settings.eta));
    }
    refuse(phaseGProblem(settings.phaseG), fmt::format("'phase_g' = {}", settings.phaseG));
    refuse(singleSamplesProblem(settings.singleSamples),
           fmt::format("'single_samples' = {}", settings.singleSamples));
    if (settings.method != ScatteringMethod::Gaussian &&
        settings.coefficients == CoefficientSource::Material) {
        measuredMaterial(settings.material);
    }
    refuse(scaleProblem(settings.scale), fmt::format("'scale' = {}", settings.scale));
}

void from_json(const nlohmann::json& json, ScatteringSettings& settings) {
    rejectUnknownKeys(
        json, "scattering",
        {"method", "material", "unit", "scale", "albedo", "max_taps", "coefficients",
         "mean_free_path_mm", "eta", "phase_g", "single_samples", "light_path", "transmission"});
    readEnum(json, "method", settings.method, kMethods, "scattering method");
    readEnum(json, "coefficients", settings.coefficients, kSources, "coefficient source");
    if (const auto found = json.find("material"); found != json.end()) {
        if (!found->is_string()) {
            throw Error("the setting 'material' must be a string");
        }
        settings.material = findMaterial(found->get<std::string>()).name;
    }
    readEnum(json, "unit", settings.unit, kUnits, "unit");
    readSetting(json, "scale", settings.scale, 0.0f, 1000.0f);
    readEnum(json, "albedo", settings.albedo, kPlacements, "albedo placement");
    readSetting(json, "max_taps", settings.maxTaps, 1, 128);
    readSetting(json, "mean_free_path_mm", settings.meanFreePathMm, -1e30f, 1e30f);
    if (const auto eta = json.find("eta"); eta != json.end()) {
        if (eta->is_null()) {
            settings.eta.reset();
        } else if (eta->is_number()) {
            settings.eta = eta->get<float>();
        } else {
            throw Error("the setting 'eta' must be a number or null (the material's)");
        }
    }
    readSetting(json, "phase_g", settings.phaseG, -1e30f, 1e30f);
    readSetting(json, "single_samples", settings.singleSamples, -1000000, 1000000);
    readEnum(json, "light_path", settings.lightPath, kLightPaths, "light path");
    readSetting(json, "transmission", settings.transmission);
    checkScatteringSettings(settings);
}

}  // namespace subscan
