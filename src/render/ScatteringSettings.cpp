#include "render/ScatteringSettings.h"

#include "render/SettingsJson.h"
#include "sss/MaterialLibrary.h"

namespace subscan {

namespace {

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
        {"material", settings.material}, {"unit", toString(settings.unit)},
        {"scale", settings.scale},       {"albedo", toString(settings.albedo)},
        {"max_taps", settings.maxTaps},
    };
}

void from_json(const nlohmann::json& json, ScatteringSettings& settings) {
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
}

}  // namespace subscan
