#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include <nlohmann/json_fwd.hpp>

namespace subscan {

/// Where the surface colour (albedo) enters the subsurface blur (d'Eon & Luebke 2007): before it
/// (colour bleeds with the light), after it (texture detail stays sharp), or √albedo on both
/// sides (the compromise).
enum class AlbedoPlacement { PreScatter, PostScatter, Split };

/// The length unit of the scan's coordinates; diffusion profiles are in millimetres.
enum class SceneUnit { Millimetre, Centimetre, Metre, Inch };

/// Which light transport the sss mode adds to the surface (DESIGN.md §6): the Gaussian blur of
/// the diffuse light (§6.1), single scattering added to the unblurred diffuse light (§6.3), or
/// single scattering added to the blurred one.
enum class ScatteringMethod { Gaussian, Single, Both };

/// Where single scattering takes σs′ and σa from: the material's measurement, or per pixel from
/// the reconstructed colour and the diffuse mean free path (§6.4).
enum class CoefficientSource { Material, Color };

/// How single scattering finds where a directional light entered on its way to a sample
/// (DESIGN.md §6.3): by marching towards it through the camera's reconstructed depth (Screen:
/// only surfaces the camera sees), or from the light's own reconstruction (LightMap: the first
/// surface the light meets, seen or not, e.g. the back of a thin part). The head light needs
/// neither: its entry lies on the sample's own line of sight.
enum class LightPath { Screen, LightMap };

/// The diffuse mean free path ld = 1/σtr of Jensen et al. 2001's measured marble (mm, R G B):
/// with it a marble-coloured scan gets marble's own σs′ and σa back from its colour.
inline constexpr glm::vec3 kMarbleMeanFreePathMm{8.51f, 5.57f, 3.95f};

/// Screen-space subsurface scattering (DESIGN.md §6).
struct ScatteringSettings {
    ScatteringMethod method = ScatteringMethod::Gaussian;
    std::string material = "marble-jimenez";  // a name from `subscan materials`
    SceneUnit unit = SceneUnit::Metre;        // most scans (Stanford, LAS) are in metres
    float scale = 1.0f;  // multiplies every radius of the profile and every mean free path
    AlbedoPlacement albedo = AlbedoPlacement::Split;
    int maxTaps = 24;  // blur taps on each side of a pixel; wider kernels take larger strides
    // Single scattering (§6.3, §6.4).
    CoefficientSource coefficients = CoefficientSource::Color;
    glm::vec3 meanFreePathMm = kMarbleMeanFreePathMm;  // ld per channel, for Color
    std::optional<float> eta;  // unset: the material's; set: overrides it for both sources
    float phaseG = 0.0f;       // Henyey-Greenstein asymmetry, -1 < g < 1
    int singleSamples = 8;     // samples along the refracted view ray
    LightPath lightPath = LightPath::LightMap;
    // Light of the directional lights through thin parts into the Gaussian blur: the light
    // map's thickness and the profile (Jimenez et al. 2010; DESIGN.md §5.9).
    bool transmission = true;

    bool operator==(const ScatteringSettings&) const = default;
};

/// The relative index of refraction single scattering uses (ScatteringSettings::eta's rule).
double scatteringEta(const ScatteringSettings& settings);

/// Millimetres per scene unit.
double millimetresPerUnit(SceneUnit unit);

std::string toString(ScatteringMethod method);
ScatteringMethod parseScatteringMethod(std::string_view text);
std::string toString(CoefficientSource source);
CoefficientSource parseCoefficientSource(std::string_view text);
std::string toString(LightPath path);
LightPath parseLightPath(std::string_view text);
std::string toString(AlbedoPlacement placement);
AlbedoPlacement parseAlbedoPlacement(std::string_view text);
std::string toString(SceneUnit unit);
SceneUnit parseSceneUnit(std::string_view text);

/// Throws subscan::Error naming the first impossible value (ld <= 0, eta < 1, |g| >= 1, ...) by
/// its key; from_json calls it, and so do the CLI's overrides.
void checkScatteringSettings(const ScatteringSettings& settings);

/// Why each value cannot be its setting's, as the rest of a sentence naming the value ("is
/// outside 1..3 (...)"), or nullopt where it can: the ranges checkScatteringSettings holds the
/// settings to, one at a time, for the command line to name its options instead of the keys.
std::optional<std::string> scaleProblem(float scale);
std::optional<std::string> meanFreePathProblem(const glm::vec3& millimetres);
std::optional<std::string> etaProblem(float eta);
std::optional<std::string> phaseGProblem(float g);
std::optional<std::string> singleSamplesProblem(int samples);

void to_json(nlohmann::json& json, const ScatteringSettings& settings);
void from_json(const nlohmann::json& json, ScatteringSettings& settings);

}  // namespace subscan
