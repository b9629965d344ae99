// The per-pixel blend of the normal pyramid, for Normals.comp and FinishSurface.comp (which
// blends level 0 itself). The pyramid is written as a storage buffer and read as a buffer
// texture (see Buffer::bindTexels). An includer that has the frame's "surfaceDepth" (+inf off
// the surface) defines NORMALS_SEE_OUTLINE 1 and binds it to SUBSCAN_IMAGE_IN0; only then can
// normals follow the surface towards the outline (SurfaceParams.normals.y).
#include "render/PullPush.glsl"
#include "shared/pyramid.glsl"
#include "shared/surface.glsl"

#ifndef NORMALS_SEE_OUTLINE
#define NORMALS_SEE_OUTLINE 0
#endif

#if NORMALS_SEE_OUTLINE
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;
#endif
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

#if NORMALS_SEE_OUTLINE
/// How many pixels the background lies from `pixel` along the nearest of the 4 axes: 1 to
/// kOutlineRings, or 0 when farther (or only the image's border, past which the surface goes
/// on). The background must go on for kOutlineRun pixels along the axis: the fill leaves
/// small holes in a surface that faces the camera, where no outline turns away (at close-ups
/// each hole drew a dark cross). Every pixel is read, outermost first: on llvmpipe loops of
/// fixed length without an exit cost a quarter of what the early exit did.
const int kOutlineRings = 3;
const int kOutlineRun = 3;
int outlineRing(ivec2 pixel) {
    int nearest = 0;
    for (int k = 0; k < 8; k += 2) {
        int run = 0;  // background pixels from `distance` outwards
        for (int distance = kOutlineRings + kOutlineRun - 1; distance >= 1; --distance) {
            ivec2 neighbour = pixel + distance * kDirections[k];
            bool background =
                insideLevel(0u, neighbour) && isinf(imageLoad(inSurfaceDepth, neighbour).r);
            run = background ? run + 1 : 0;
            if (distance <= kOutlineRings && run >= kOutlineRun &&
                (nearest == 0 || distance < nearest)) {
                nearest = distance;
            }
        }
    }
    return nearest;
}

/// `normal`, blended at fractional level `smoothing` from the unit normals `lower` and `upper`
/// of the levels around it, turned away from the eye to where the surface at view-space
/// `position`, `ring` pixels in from the outline, would face on the profile the two levels
/// show. Where a smooth surface turns away at an outline, its depth grows as the square root of
/// the distance s to the outline, so the normal's component c towards the eye goes as √s. A
/// level's normal near the outline is the surface's about 2^(level+1) pixels in (its tangents
/// reach one texel inwards from a texel the outline cuts; measured on a sphere: 4 pixels at
/// level 1), the next level's twice as far: their ratio q = c_upper / c_lower is √2 on that
/// profile and 1 on a flat surface that ends (a crease, a scan's border). So the pixel's own c,
/// at s = ring − 1/2, is c / q^log2(2^(smoothing+1) / s); q is kept within [1, √2], so that
/// noise can neither tilt a normal towards the eye nor past the profile of a smooth outline.
vec3 followProfileToOutline(vec3 normal, vec3 lower, vec3 upper, float smoothing, vec3 position,
                            int ring) {
    vec3 toEye = towardsEye(position);
    float c = dot(normal, toEye);
    float ratio = clamp(dot(upper, toEye) / max(dot(lower, toEye), 1e-4), 1.0, sqrt(2.0));
    float steps = max(smoothing + 1.0 - log2(float(ring) - 0.5), 0.0);
    vec3 across = normal - c * toEye;
    float acrossLength = length(across);
    if (acrossLength < 1e-6) {
        return normal;  // facing the eye: no direction to turn in
    }
    float turned = c / pow(ratio, steps);
    return turned * toEye + sqrt(max(1.0 - turned * turned, 0.0)) * (across / acrossLength);
}
#endif

/// A level's bilinear normal as a unit vector, facing the camera where its taps cancel.
vec3 unitOrFacing(vec3 normal) {
    float length2 = dot(normal, normal);
    return length2 > 0.0 ? normal * inversesqrt(length2) : vec3(0.0, 0.0, 1.0);
}

/// The view-space normal of surface pixel `texel` at `depth`. With the points' own normals: the
/// push of their pull-push to level 0. Else the paper's: the normals of the two pyramid
/// levels around its smoothing level, blended, and near the outline followed towards it
/// (followProfileToOutline) when the settings ask. `spacingRatio`: spacingRatioAt(texel), which
/// scales the smoothing radius.
vec3 blendedNormal(ivec2 texel, float depth, float spacingRatio) {
    if (surface.normals.z > 0.5) {
        return unitOrFacing(pushedNormal(0u, texel));  // the points' own (PullPush.glsl)
    }
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
    vec3 lowerNormal = normalOnLevel(lower, lowerPlace, window);
    vec3 upperNormal = normalOnLevel(upper, upperPlace, window);
    vec3 normal = unitOrFacing(mix(lowerNormal, upperNormal, smoothing - float(lower)));
#if NORMALS_SEE_OUTLINE
    if (surface.normals.y > 0.0) {
        int ring = outlineRing(texel);
        if (ring > 0) {
            normal = followProfileToOutline(normal, unitOrFacing(lowerNormal),
                                            unitOrFacing(upperNormal), smoothing,
                                            viewPositionAt(window, depth), ring);
        }
    }
#endif
    return normal;
}
