// Binding indices and GPU struct layouts, included by both C++ (src/) and GLSL (shaders/):
// each number and each layout exists exactly once. Structs use only 16-byte members (vec4,
// uvec4, mat4) or scalars in groups of four, so std140 and C++ agree; C++ static_asserts check
// the sizes.
#ifndef SUBSCAN_BINDINGS_H
#define SUBSCAN_BINDINGS_H

#ifdef __cplusplus
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
namespace subscan::gpu {
using uint = std::uint32_t;
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using mat4 = glm::mat4;
#endif

// The macros keep their comments beside them, aligned, which the formatter would break.
// clang-format off
// ---- uniform blocks (std140) ----
#define SUBSCAN_UBO_FRAME 0
#define SUBSCAN_UBO_PASS 1
#define SUBSCAN_UBO_PYRAMID 2
#define SUBSCAN_UBO_SURFACE 3
#define SUBSCAN_UBO_LIGHTS 4  // ShadeParams for a pass other than Shade that needs the lights
#define SUBSCAN_UBO_TEMPORAL 5  // TemporalParams (Temporal, and FinishSurface's fused filter)

// ---- plain uniforms ----
#define SUBSCAN_UNIFORM_LEVEL 0    // uint: the pyramid level a per-level dispatch works on
#define SUBSCAN_UNIFORM_ORIGIN 1   // ivec2: the texel of invocation (0, 0) (shared/region.glsl)
#define SUBSCAN_UNIFORM_DIVISOR 2  // int: output pixels per pipeline pixel and side (Present)
#define SUBSCAN_UNIFORM_END 3      // ivec2: the texel past the region's last (shared/region.glsl)
#define SUBSCAN_UNIFORM_FADE 4     // float: the new picture's weight (the viewer's CrossFade)

// Beyond its outermost points a sparse surface is kept for this share of the expected gap, times
// 1 - 1 / (local spacing ratio) (FillRemoval.glsl's kBeyondOutermostPoints says why and how it
// was measured); the passes' region (MinDepthPyramidPass) reaches that far beyond the points.
#define SUBSCAN_BEYOND_OUTERMOST_POINTS 0.75
// The image border encloses a gap's direction up to this many expected gaps away where points
// reach it within this many degrees of the direction (FillRemoval.glsl's bordersReached).
#define SUBSCAN_BORDER_POINTS_REACH 3.0
#define SUBSCAN_BORDER_POINTS_CONE_DEGREES 67.5

// ---- shader storage blocks (std430) ----
#define SUBSCAN_SSBO_DEPTH_INDEX 4    // uint64 per pixel: depth bits << 32 | point index
#define SUBSCAN_SSBO_PYRAMID 5        // float per texel, all levels: min depth
#define SUBSCAN_SSBO_PULL_VALUES 6    // vec4 per texel, all levels: w * (depth, r, g, b)
#define SUBSCAN_SSBO_PULL_WEIGHTS 7   // vec2 per texel, all levels: clamped weight w and
                                      // w * the local spacing (in h) of the points pulled
#define SUBSCAN_SSBO_PUSH_VALUES 8    // vec4 per texel, levels >= 1: complete (depth, r, g, b)
#define SUBSCAN_SSBO_NORMALS 9        // vec4 per texel: screen-space normals (levels >= 1):
                                      // view-space normal, w unused; point normals (all levels):
                                      // pulled w_n * normal, w_n, pushed in place (levels >= 1)
                                      // to the complete normal, 1
#define SUBSCAN_SSBO_POINT_BOUNDS 10  // ivec4: min x, min y, max x, max y of occupied texels
#define SUBSCAN_SSBO_FILL_REACH 11    // uint per texel, all levels: per direction, 4 bits of level
#define SUBSCAN_SSBO_COLOR_SUMS 12    // uvec4 per pixel: fixed-point linear RGB sums, point count
#define SUBSCAN_SSBO_NORMAL_SUMS 20   // 3 int per pixel, with the normal blend: fixed-point
                                      // sums of the view-space normals facing the eye
#define SUBSCAN_SSBO_CLEAR 13         // uint words GpuClear fills (its own binding: no pass's)
#define SUBSCAN_SSBO_OCCUPANCY 14     // uint per pixel: which of its 4x4 sub-cells hold points
#define SUBSCAN_SSBO_POINT_CENTROIDS 15  // uint per texel, levels >= 1: where in the texel its
                                         // points lie on average (unorm16x2 of the texel)
#define SUBSCAN_SSBO_FILL_SPARSE 16      // uint per level-1 texel: what it adds to its pixels'
                                         // gap test (FillRemoval.glsl's sparseEnclosure)
#define SUBSCAN_SSBO_FRONT_SPACING 18     // float per texel, all levels, with the local
                                         // spacing: the spacing ratio of the texel's nearest
                                         // point (the min-depth pyramid's)
#define SUBSCAN_SSBO_PULL_AXES 19         // vec4 per texel, all levels, with the local
                                         // spacing: over the visible pixels the texel covers
                                         // on the front surface (as the pull chooses it), the
                                         // sum of their across-lines axes (xy,
                                         // SUBSCAN_SSBO_ACROSS_LINES) and their count (z)
#define SUBSCAN_SSBO_ACROSS_LINES 17     // uint per pixel, with the local spacing: the
                                         // winning point's vector across its scan lines on
                                         // screen as a doubled-angle axis of length
                                         // 1 - w / |vector| (half2; 0 where its lines are no
                                         // farther apart than its spacing w)

// ---- buffer textures, read with texelFetch (Buffer::bindTexels) ----
#define SUBSCAN_TEXELS_PYRAMID 0       // r32f view of SUBSCAN_SSBO_PYRAMID
#define SUBSCAN_TEXELS_PULL_VALUES 1   // rgba32f view of SUBSCAN_SSBO_PULL_VALUES
#define SUBSCAN_TEXELS_PULL_WEIGHTS 2  // rg32f view of SUBSCAN_SSBO_PULL_WEIGHTS
#define SUBSCAN_TEXELS_PUSH_VALUES 3   // rgba32f view of SUBSCAN_SSBO_PUSH_VALUES
#define SUBSCAN_TEXELS_NORMALS 4       // rgba32f view of SUBSCAN_SSBO_NORMALS
#define SUBSCAN_TEXELS_FILL_REACH 5    // r32ui view of SUBSCAN_SSBO_FILL_REACH
#define SUBSCAN_TEXELS_POSITIONS 6     // r32f: x, y, z per point (cloud-relative), one chunk
#define SUBSCAN_TEXELS_FRONT_SPACING 6  // r32f view of SUBSCAN_SSBO_FRONT_SPACING (shares its
                                        // unit with the points, which the pyramid and hidden
                                        // point removal never read)
#define SUBSCAN_TEXELS_COLORS 7        // r32ui: RGBA8, sRGB-encoded, per point, one chunk
#define SUBSCAN_TEXELS_PULL_AXES 7     // rgba32f view of SUBSCAN_SSBO_PULL_AXES (shares its unit
                                       // with the points' colours, which only the rasterizer
                                       // reads)
#define SUBSCAN_TEXELS_ALBEDO_ROOTS 8  // r32f: sqrt(1 - reduced albedo) by total reflectance
#define SUBSCAN_TEXELS_LOCAL_SPACING 9  // rgba16f per point, one chunk (estimateLocalSpacing)
#define SUBSCAN_TEXELS_POINT_NORMALS 10    // r32ui per point, one chunk: octahedral snorm16x2
                                           // unit normal, 0 for none (the rasterizer's; it
                                           // shares its unit with the first light map, which
                                           // it never reads)
#define SUBSCAN_TEXELS_POINT_CENTROIDS 14  // r32ui view of SUBSCAN_SSBO_POINT_CENTROIDS (after
                                           // the light maps: 16 units are all GL promises)
#define SUBSCAN_TEXELS_FILL_SPARSE 15      // r32ui view of SUBSCAN_SSBO_FILL_SPARSE

// ---- textures read with texelFetch ----
// sampler2D per directional light (units 10 .. 10 + SUBSCAN_MAX_LIGHTS - 1): its light map
// (shared/lightmap.glsl)
#define SUBSCAN_TEXTURES_LIGHT_MAPS 10

// ---- images ----
#define SUBSCAN_IMAGE_OUT0 0
#define SUBSCAN_IMAGE_OUT1 1
#define SUBSCAN_IMAGE_OUT2 2
#define SUBSCAN_IMAGE_OUT3 3
#define SUBSCAN_IMAGE_IN0 4
#define SUBSCAN_IMAGE_IN1 5
#define SUBSCAN_IMAGE_IN2 6
#define SUBSCAN_IMAGE_IN3 7

// ---- vertex attributes (GL_POINTS baseline) ----
#define SUBSCAN_ATTRIBUTE_POSITION 0
#define SUBSCAN_ATTRIBUTE_COLOR 1

// ---- limits ----
#define SUBSCAN_MAX_PYRAMID_LEVELS 16  // 1 + ceil(log2(65536)): the largest image side
#define SUBSCAN_MAX_LIGHTS 4           // directional lights besides the head light
#define SUBSCAN_MAX_PROFILE_GAUSSIANS 12  // terms of a diffusion profile the shading transmits

// ---- compute work group sizes ----
#define SUBSCAN_POINTS_GROUP_SIZE 256
#define SUBSCAN_IMAGE_GROUP_SIZE 8
#define SUBSCAN_CLEAR_GROUP_SIZE 256  // GpuClear's buffer fill, one word per invocation and step
// clang-format on

// Per-frame camera and viewport. Images have row 0 at the top, like the PNG output.
struct FrameParams {
    mat4 viewFromCloud;  // cloud-relative positions -> view space (built in double on the CPU)
    mat4 projection;     // view -> clip, OpenGL convention
    vec4 viewport;       // width, height, 1 / width, 1 / height
    vec4 depthRange;     // near, far, focal length in pixels (orthographic: pixels per unit),
                         // w: 1 for an orthographic view (a light's), 0 for a pinhole camera
    vec4 background;     // linear RGB, alpha unused
    vec4 jitter;         // xy: pixels the picture is shifted by (Camera::jitterPixels), zw unused
};

// RasterizePoints: which slice of the cloud this dispatch covers.
struct RasterParams {
    uint firstPoint;   // global index of the chunk's first point
    uint pointCount;   // points in this chunk
    uint pixelCount;   // width * height
    float colorBlend;  // points within this relative depth of a pixel's nearest share its colour
    vec4 normalBlend;  // x: points within this many pixel widths behind a pixel's nearest
                       // share their normal (with the points' own normals), yzw unused
};
// Fixed-point units per 1.0 of linear colour in SUBSCAN_SSBO_COLOR_SUMS: 2^14, so that the
// darkest 8-bit sRGB step (3e-4) is 5 units, and 2^32 / 2^14 = 262144 white points per pixel
// fit before a sum overflows.
#define SUBSCAN_COLOR_SUM_SCALE 16384.0
// Fixed-point units per 1.0 of a normal's component in SUBSCAN_SSBO_NORMAL_SUMS: 2^12 keeps a
// unit normal's direction within 0.02 degrees, and 2^31 / 2^12 = 524288 points per pixel fit.
#define SUBSCAN_NORMAL_SUM_SCALE 4096.0

// DrawPoints (GL_POINTS baselines).
struct DrawParams {
    vec4 pointSize;  // x: size in pixels
};

// Where each level of an image pyramid sits in its buffer. Level R is ceil(W / 2^R) x
// ceil(H / 2^R); the last level is 1x1.
struct PyramidLayout {
    uvec4 levels[SUBSCAN_MAX_PYRAMID_LEVELS];  // x: first texel, y: width, z: height, w: unused
    uvec4 info;                                // x: number of levels, y: total texels
};

// The reconstruction passes (HiddenPointRemoval, PullPush, FillRemoval, Normals). World radii
// are in scene units for the global spacing h; with local spacing each pixel's ratio
// (RasterizePoints.comp) shrinks HPR's (min(ratio, 1)) and grows the fill's and the normals'
// (PullPush.glsl's spacingRatioAt, at least 1). Each pass turns its radius into a pyramid
// level per pixel: level = log2(radius * focal length / depth).
struct SurfaceParams {
    vec4 visibility;  // x: HPR radius, y: threshold tau, z: edge rule (1 or 0), w: unused
    vec4 fill;        // x: radius of the expected gap, y: directions that must find points,
                      // z: pull depth slope (texel widths), w: 1 to place a dense
                      // cloud's outline by its points' sub-pixel cells (SUBSCAN_SSBO_OCCUPANCY)
    vec4 normals;     // x: smoothing radius, y: 1 to extrapolate them towards the outline
                      // (screen-space normals), z: 1 for the points' own normals
    vec4 spacing;     // x: 1 when the points carry their local spacing, else 0
};

// Deferred shading; directions are in view space, pointing towards the light.
struct ShadeParams {
    vec4 headLight;  // rgb: radiance of a light at the eye
    vec4 ambient;    // rgb: ambient radiance
    vec4 specular;   // x: specular reflectance, y: Blinn-Phong exponent
    vec4 lightDirection[SUBSCAN_MAX_LIGHTS];
    vec4 lightColor[SUBSCAN_MAX_LIGHTS];
    uvec4 lightCount;  // x: how many of the directional lights are used
    // Shadows (LightMaps): per light, view space -> its light map's view space, and the map's
    // x: texels per scene unit, y: width, z: height (texels), w: 1 when it casts shadows.
    mat4 lightFromView[SUBSCAN_MAX_LIGHTS];
    vec4 lightMap[SUBSCAN_MAX_LIGHTS];
    vec4 shadow;  // x: depth bias, y: width of a shadow's soft edge (both scene units)
    // Transmission through thin parts (sss mode): the diffusion profile's Gaussians, rgb: weight,
    // w: variance (scene units²); count.x of them, 0 for none.
    vec4 profile[SUBSCAN_MAX_PROFILE_GAUSSIANS];
    uvec4 profileCount;
};

// SubsurfaceScattering: one dispatch of the blur chain (DESIGN.md §6.1).
struct ScatterParams {
    vec4 blur;     // x: standard deviation in scene units, y: most taps on each side,
                   // z: 1 for the vertical pass, 0 for the horizontal one
    vec4 weight;   // rgb: weight of the Gaussian this dispatch finishes (or starts, when unblurred)
    uvec4 albedo;  // x: where the albedo enters: 0 before the blur, 1 after it, 2 split (sqrt both)
};

// SingleScattering (DESIGN.md §6.3, §6.4). Coefficients are in mm⁻¹ and lengths in mm as the
// settings give them; medium.z converts them to the scene's unit.
struct SingleScatterParams {
    vec4 sigmaSPrime;   // rgb: the material's reduced scattering coefficient (material source)
    vec4 sigmaA;        // rgb: the material's absorption coefficient (material source)
    vec4 meanFreePath;  // rgb: diffuse mean free path ld (colour source)
    vec4 medium;        // x: eta, y: Henyey-Greenstein g, z: mm per scene unit / scale
    vec4 sampling;      // x: samples along the refracted view ray, y: entries of the albedo
                        // root table, z: total reflectance of its last entry, w: most march steps
    uvec4 flags;        // x: 1 for coefficients from the colour, 0 for the material's;
                        // y: 1 to write the term and the coefficients alone (exports)
};

// Temporal (DESIGN.md §5 step 10): the new frame blended into the previous result reprojected
// to it.
struct TemporalParams {
    mat4 previousFromView;    // this frame's view space -> the previous frame's view space
    mat4 previousProjection;  // the previous frame's projection without its jitter
    vec4 blend;   // x: least weight of the new frame while the camera moves, y: clip sigma,
                  // z: most frames a still camera averages, w: unused
    vec4 depth;   // x: depth difference (scene units) beyond which the history saw another surface
    uvec4 flags;  // x: 1 when the history was reprojected last frame (a still camera then
                  // weighs it as one frame)
};

#ifdef __cplusplus
static_assert(sizeof(TemporalParams) == 2 * 64 + 3 * 16);
static_assert(sizeof(ScatterParams) == 48);
static_assert(sizeof(SingleScatterParams) == 96);
static_assert(sizeof(PyramidLayout) == (SUBSCAN_MAX_PYRAMID_LEVELS + 1) * 16);
static_assert(sizeof(SurfaceParams) == 64);
static_assert(sizeof(ShadeParams) == 3 * 16 + 3 * SUBSCAN_MAX_LIGHTS * 16 + 16 +
                                         SUBSCAN_MAX_LIGHTS * 64 + 16 +
                                         SUBSCAN_MAX_PROFILE_GAUSSIANS * 16 + 16);
static_assert(sizeof(FrameParams) == 2 * 64 + 4 * 16);
static_assert(sizeof(RasterParams) == 32);
static_assert(sizeof(DrawParams) == 16);
static_assert(SUBSCAN_TEXELS_POINT_NORMALS >= SUBSCAN_TEXTURES_LIGHT_MAPS &&
              SUBSCAN_TEXELS_POINT_NORMALS < SUBSCAN_TEXTURES_LIGHT_MAPS + SUBSCAN_MAX_LIGHTS &&
              SUBSCAN_TEXELS_POINT_NORMALS > SUBSCAN_TEXELS_LOCAL_SPACING);
static_assert(SUBSCAN_TEXELS_POINT_CENTROIDS >= SUBSCAN_TEXTURES_LIGHT_MAPS + SUBSCAN_MAX_LIGHTS &&
              SUBSCAN_TEXELS_FILL_SPARSE > SUBSCAN_TEXELS_POINT_CENTROIDS &&
              SUBSCAN_TEXELS_FILL_SPARSE < 16);
}  // namespace subscan::gpu
#endif

#endif
