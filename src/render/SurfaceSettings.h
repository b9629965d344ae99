#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

namespace subscan {

/// Where the surface's normals come from (DESIGN.md §5 step 5): the points' own (the file's, or
/// estimated once by PCA of their neighbours; the rasterizer blends a pixel's nearest ones,
/// RasterSettings::normalBlend, and pull-push carries them into the gaps), or the paper's, rebuilt
/// from the filled depth for every view. Auto: the points' where the renderer has them, else the
/// screen's. The renderer resolves Auto before its passes see the settings.
enum class NormalSource { Auto, Points, Screen };
/// Names as the CLI and JSON spell them; the parser throws subscan::Error listing the choices.
std::string toString(NormalSource source);
NormalSource parseNormalSource(std::string_view text);

/// The screen-space reconstruction (DESIGN.md §5 steps 3-5). Radii are multiples of the point
/// spacing h, so the defaults fit any scan at any scale; each pass turns its radius into a
/// pyramid level per pixel: level = log2(radius * h * focal length / depth).
struct SurfaceSettings {
    // HPR looks this far for occluders (x h); its coarsest level has texels of 1/2 to 1 radius.
    // With 4 h, close-ups let the back show through the gaps between points (bench/README.md,
    // "Hidden points at close-ups").
    float visibilityRadius = 6.0f;
    float visibilityThreshold = 0.3f;  // tau: mean of the 8 smallest omegas for "visible"
    bool edgeRule = true;              // the paper's silhouette rule
    float pullDepthSlope = 8.0f;       // pull keeps children within this many texel widths
                                       // behind the nearest one (the front-most surface)
    float fillRadius = 1.0f;           // the expected gap between points (x h)
    int fillDirections = 8;            // of 8 directions, how many must find points
    NormalSource normals = NormalSource::Auto;
    float normalRadius = 1.5f;     // screen-space normals' smoothing (x h)
    bool restrictToPoints = true;  // passes skip the screen outside the points' bounds
    // Radii scale with each point's local spacing where the renderer has it
    // (estimatePointSpacing), instead of the one global h.
    bool localSpacing = true;
    // A dense cloud's outline runs through its outermost pixels where their points' 4x4
    // sub-pixel cells say it does (more than about half covered: kept), instead of every pixel
    // a point falls in being surface (half a pixel too far out on average).
    bool subpixelOutline = true;
    // Normals within 3 pixels of the outline against the background extrapolated to it along
    // the depth profile the two smoothing levels show (Normals.glsl): a smoothed normal there
    // is the surface's a few pixels further in, where a round object's surface faces the
    // camera more, so rims came out too bright.
    bool outlineNormals = true;

    bool operator==(const SurfaceSettings&) const = default;
};

/// Where a directional light's direction is fixed: in the scene (World; it stays put while
/// the camera moves) or to the camera (View: x right, y up, z towards the eye; it turns with
/// the camera, like a photographer's key light, and its light map is rebuilt whenever the
/// camera turns).
enum class LightSpace { World, View };

struct DirectionalLight {
    glm::vec3 direction{0.0f, 1.0f, 0.0f};  // towards the light, in `space`
    glm::vec3 radiance{1.0f};
    LightSpace space = LightSpace::World;

    bool operator==(const DirectionalLight&) const = default;
};

/// The unit direction towards `light` in the scene's coordinates for a camera whose
/// world-to-view matrix is `view`.
glm::dvec3 towardsLightInWorld(const DirectionalLight& light, const glm::dmat4& view);

/// Explicit light map resolutions (ShadingSettings::lightMapResolution).
inline constexpr int kMinLightMapResolution = 16;
inline constexpr int kMaxLightMapResolution = 8192;

/// Deferred shading (DESIGN.md §5 step 6). Radiances are linear RGB.
struct ShadingSettings {
    glm::vec3 headLight{0.85f};
    glm::vec3 ambient{0.15f};
    float specular = 0.08f;                // Blinn-Phong reflectance
    float shininess = 40.0f;               // Blinn-Phong exponent
    std::vector<DirectionalLight> lights;  // at most SUBSCAN_MAX_LIGHTS
    // Shadows of the directional lights (the head light casts none), from each light's own
    // reconstruction of the cloud: its light map (DESIGN.md §5.9, render/LightMaps.h).
    bool shadows = true;
    float shadowBias = 2.0f;      // x h: how far behind the light map's surface shadow begins
    float shadowSoftness = 2.0f;  // x h: the width over which a shadow's edge fades (>= a texel)
    int lightMapResolution = 0;   // texels along a light map's longer side; 0: from h (LightMaps)

    bool operator==(const ShadingSettings&) const = default;
};

void to_json(nlohmann::json& json, const SurfaceSettings& settings);
void from_json(const nlohmann::json& json, SurfaceSettings& settings);
void to_json(nlohmann::json& json, const ShadingSettings& settings);
void from_json(const nlohmann::json& json, ShadingSettings& settings);

}  // namespace subscan
