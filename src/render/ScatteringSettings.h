#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

namespace subscan {

/// Where the surface colour (albedo) enters the subsurface blur (d'Eon & Luebke 2007): before it
/// (colour bleeds with the light), after it (texture detail stays sharp), or √albedo on both
/// sides (the compromise).
enum class AlbedoPlacement { PreScatter, PostScatter, Split };

/// The length unit of the scan's coordinates; diffusion profiles are in millimetres.
enum class SceneUnit { Millimetre, Centimetre, Metre, Inch };

/// Screen-space subsurface scattering (DESIGN.md §6.1).
struct ScatteringSettings {
    std::string material = "marble-jimenez";  // a name from `subscan materials`
    SceneUnit unit = SceneUnit::Metre;        // most scans (Stanford, LAS) are in metres
    float scale = 1.0f;                       // multiplies every radius of the profile
    AlbedoPlacement albedo = AlbedoPlacement::Split;
    int maxTaps = 24;  // blur taps on each side of a pixel; wider kernels take larger strides
};

/// Millimetres per scene unit.
double millimetresPerUnit(SceneUnit unit);

std::string toString(AlbedoPlacement placement);
AlbedoPlacement parseAlbedoPlacement(std::string_view text);
std::string toString(SceneUnit unit);
SceneUnit parseSceneUnit(std::string_view text);

void to_json(nlohmann::json& json, const ScatteringSettings& settings);
void from_json(const nlohmann::json& json, ScatteringSettings& settings);

}  // namespace subscan
