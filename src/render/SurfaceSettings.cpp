#include "render/SurfaceSettings.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "render/SettingsJson.h"
#include "shared/bindings.h"

namespace subscan {

namespace {

constexpr std::pair<NormalSource, std::string_view> kNormalSources[] = {
    {NormalSource::Auto, "auto"},
    {NormalSource::Points, "points"},
    {NormalSource::Screen, "screen"},
};

}  // namespace

std::string toString(NormalSource source) {
    return nameOf(kNormalSources, source);
}

NormalSource parseNormalSource(std::string_view text) {
    return parseName(kNormalSources, text, "normal source");
}

void to_json(nlohmann::json& json, const SurfaceSettings& settings) {
    json = {
        {"visibility_radius", settings.visibilityRadius},
        {"visibility_threshold", settings.visibilityThreshold},
        {"edge_rule", settings.edgeRule},
        {"pull_depth_slope", settings.pullDepthSlope},
        {"fill_radius", settings.fillRadius},
        {"fill_directions", settings.fillDirections},
        {"normals", nameOf(kNormalSources, settings.normals)},
        {"normal_radius", settings.normalRadius},
        {"restrict_to_points", settings.restrictToPoints},
        {"local_spacing", settings.localSpacing},
        {"subpixel_outline", settings.subpixelOutline},
        {"outline_normals", settings.outlineNormals},
    };
}

void from_json(const nlohmann::json& json, SurfaceSettings& settings) {
    rejectUnknownKeys(
        json, "surface",
        {"visibility_radius", "visibility_threshold", "edge_rule", "pull_depth_slope",
         "fill_radius", "fill_directions", "normals", "normal_radius", "restrict_to_points",
         "local_spacing", "subpixel_outline", "outline_normals"});
    readSetting(json, "visibility_radius", settings.visibilityRadius, 0.1f, 1000.0f);
    readSetting(json, "visibility_threshold", settings.visibilityThreshold, 0.0f, 2.0f);
    readSetting(json, "edge_rule", settings.edgeRule);
    readSetting(json, "pull_depth_slope", settings.pullDepthSlope, 0.1f, 1e6f);
    readSetting(json, "fill_radius", settings.fillRadius, 0.1f, 1000.0f);
    readSetting(json, "fill_directions", settings.fillDirections, 1, 8);
    readEnum(json, "normals", settings.normals, kNormalSources, "normal source");
    readSetting(json, "normal_radius", settings.normalRadius, 0.1f, 1000.0f);
    readSetting(json, "restrict_to_points", settings.restrictToPoints);
    readSetting(json, "local_spacing", settings.localSpacing);
    readSetting(json, "subpixel_outline", settings.subpixelOutline);
    readSetting(json, "outline_normals", settings.outlineNormals);
}

namespace {

constexpr std::pair<LightSpace, std::string_view> kLightSpaces[] = {
    {LightSpace::World, "world"},
    {LightSpace::View, "view"},
};

}  // namespace

glm::dvec3 towardsLightInWorld(const DirectionalLight& light, const glm::dmat4& view) {
    const glm::dvec3 direction = glm::normalize(glm::dvec3(light.direction));
    if (light.space == LightSpace::World) {
        return direction;
    }
    // View space -> world: the transpose of the view's rotation.
    return glm::normalize(glm::transpose(glm::dmat3(view)) * direction);
}

void to_json(nlohmann::json& json, const ShadingSettings& settings) {
    nlohmann::json lights = nlohmann::json::array();
    for (const DirectionalLight& light : settings.lights) {
        lights.push_back({{"direction", toJson(light.direction)},
                          {"radiance", toJson(light.radiance)},
                          {"space", nameOf(kLightSpaces, light.space)}});
    }
    json = {
        {"head_light", toJson(settings.headLight)},
        {"ambient", toJson(settings.ambient)},
        {"specular", settings.specular},
        {"shininess", settings.shininess},
        {"lights", lights},
        {"shadows", settings.shadows},
        {"shadow_bias", settings.shadowBias},
        {"shadow_softness", settings.shadowSoftness},
        {"light_map_resolution", settings.lightMapResolution},
    };
}

void from_json(const nlohmann::json& json, ShadingSettings& settings) {
    rejectUnknownKeys(json, "shading",
                      {"head_light", "ambient", "specular", "shininess", "lights", "shadows",
                       "shadow_bias", "shadow_softness", "light_map_resolution"});
    readSetting(json, "head_light", settings.headLight, 0.0f, 100.0f);
    readSetting(json, "ambient", settings.ambient, 0.0f, 100.0f);
    readSetting(json, "specular", settings.specular, 0.0f, 1.0f);
    readSetting(json, "shininess", settings.shininess, 1.0f, 10000.0f);
    readSetting(json, "shadows", settings.shadows);
    readSetting(json, "shadow_bias", settings.shadowBias, 0.0f, 1000.0f);
    readSetting(json, "shadow_softness", settings.shadowSoftness, 0.0f, 1000.0f);
    readSetting(json, "light_map_resolution", settings.lightMapResolution, 0,
                kMaxLightMapResolution);
    if (settings.lightMapResolution != 0 && settings.lightMapResolution < kMinLightMapResolution) {
        throw Error(
            fmt::format("the setting 'light_map_resolution' must be 0 (from the point "
                        "spacing) or {} to {}",
                        kMinLightMapResolution, kMaxLightMapResolution));
    }
    if (const auto lights = json.find("lights"); lights != json.end()) {
        if (!lights->is_array() || lights->size() > SUBSCAN_MAX_LIGHTS) {
            throw Error(fmt::format("the setting 'lights' must be a list of at most {} lights",
                                    SUBSCAN_MAX_LIGHTS));
        }
        settings.lights.clear();
        for (const nlohmann::json& entry : *lights) {
            DirectionalLight light;
            rejectUnknownKeys(entry, "lights", {"direction", "radiance", "space"});
            readSetting(entry, "direction", light.direction, -1e6f, 1e6f);
            readSetting(entry, "radiance", light.radiance, 0.0f, 100.0f);
            readEnum(entry, "space", light.space, kLightSpaces, "light space");
            if (!(glm::dot(light.direction, light.direction) > 0.0f)) {
                throw Error("a light's 'direction' must not be zero");
            }
            settings.lights.push_back(light);
        }
    }
}

}  // namespace subscan
