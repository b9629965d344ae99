// The per-pixel blend of the normal pyramid, for Normals.comp and FinishSurface.comp (which
// blends level 0 itself). The pyramid is written as a storage buffer and read as a buffer
// texture (see Buffer::bindTexels).
#include "render/PullPush.glsl"
#include "shared/pyramid.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_NORMALS) uniform samplerBuffer normalTexels;
const float kFillNormalWeight = 1e-3;

/// The bilinear tap of a level's normals at `window`, each texel weighed also by how much of it
/// points cover (its pull weight), so that a silhouette pixel takes its normal from the surface
/// rather than from the fill beyond it. The floor keeps taps that all lie in fill an even
/// bilinear mix. Unnormalised on purpose: in the mix of two levels, the one whose taps points
/// cover more counts more.
vec3 normalOnLevel(uint normalLevel, LevelLayout place, vec2 window) {
    ivec2 texels[4];
    float weights[4];
    bilinearTexels(normalLevel, place, window, texels, weights);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 4; ++i) {
        uint index = texelIndex(place, texels[i]);
        float covered = max(pullWeightAt(index), kFillNormalWeight);
        sum += weights[i] * covered * texelFetch(normalTexels, int(index)).xyz;
    }
    return sum;
}

/// The view-space normal of surface pixel `texel` at `depth`: the normals of the two pyramid
/// levels around its smoothing level, blended. `spacingRatio`: spacingRatioAt(texel), which
/// scales the smoothing radius.
vec3 blendedNormal(ivec2 texel, float depth, float spacingRatio) {
    // Level 1 at least: where points are denser than pixels, neighbouring pixels are closer
    // than the scanner's noise allows a slope to be measured over.
    float smoothing = clamp(levelForRadius(surface.normals.x * spacingRatio, depth), 1.0,
                            float(levelCount() - 1u));
    uint lower = uint(smoothing);
    uint upper = min(lower + 1u, levelCount() - 1u);
    // The levels differ between pixels: their layouts are read once (each read of the layout
    // block at a varying level is a gather), the upper one derived from the lower.
    LevelLayout lowerPlace = levelLayout(lower);
    LevelLayout upperPlace = upper == lower ? lowerPlace : nextLevel(lowerPlace);
    vec2 window = vec2(texel) + 0.5;
    vec3 normal = mix(normalOnLevel(lower, lowerPlace, window),
                      normalOnLevel(upper, upperPlace, window), smoothing - float(lower));
    float length2 = dot(normal, normal);
    return length2 > 0.0 ? normal * inversesqrt(length2) : vec3(0.0, 0.0, 1.0);
}
