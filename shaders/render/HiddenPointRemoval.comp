#version 450
// Hidden point removal on the min-depth pyramid (paper §4; Pintus 2011, Bouchiba 2018).
// For a pixel holding a point x, in each of 8 directions look at the neighbouring texel on
// every level up to L(x) and keep the smallest
//     omega(x, y) = 1 - dot(normalize(y - x), normalize(-x)),
// i.e. the neighbour y that rises most towards the camera. x is visible when the mean of the 8
// smallest omegas reaches tau, or (the paper's edge rule) when 3 consecutive directions occlude
// while at least 3 others are open: x then lies just beyond an occluder's silhouette.
// Near the image's border a direction's walk is cut short where its texel reaches past the image
// (odd sizes: where the image fills it only in part). Its omega then weighs in the mean by the
// share of levels it saw, and it takes no part in the edge rule. Counted in full as open, such
// directions let points behind the surface near the border pass as visible; left out
// entirely, the few directions left hid the surface itself in the image's corners.
// The search radius is the settings' multiple of h, shrunk where the point's local spacing (the
// "color" image's alpha, RasterizePoints.comp) is smaller. The radius must span the gaps of the
// surface in front, not the point's own: a far, sparse background behind a near, dense object
// would otherwise search past the object's silhouette (measured: the table scene from its
// sensor lost 0.3 % of its measured cells, a station's views 0.5 % coverage), while for a
// point denser than h what lies in front of it is, for a station or a depth camera, nearer
// and at least as dense. Seen from elsewhere it need not be (a station's sparse far wall in
// front of its dense near ground, seen from above): with the local spacing, where a neighbour
// on the walk's last level occludes x, the walk goes on until it spans two expected gaps of
// that neighbour's surface ("frontSpacing", MinDepthPyramid.comp), at its depth. A much nearer
// surface near x, in front of it or not yet seen by the walk, extends the walk too (below).
#include "shared/pyramid.glsl"
#include "shared/region.glsl"
#include "shared/surface.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_TEXELS_PYRAMID) uniform samplerBuffer minDepthTexels;
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inColor;
layout(binding = SUBSCAN_IMAGE_OUT0, r8) writeonly uniform image2D outVisibility;
layout(binding = SUBSCAN_TEXELS_FRONT_SPACING) uniform samplerBuffer frontSpacingTexels;

// The pixels of this work group that hold a point, gathered so that the first invocations test
// them together: llvmpipe runs 8 invocations in lock-step, and on close-ups, where points are
// sparse and L(x) is large, most lanes would otherwise idle through their neighbours' walks.
shared uint occupied[gl_WorkGroupSize.x * gl_WorkGroupSize.y];
shared uint occupiedCount;

// The radius is projected at x's depth, but the gaps it must span are the occluder's: seen
// through a gap of a much nearer surface (the front of a randomly sampled sphere, a close-up),
// the radius at x's depth fell short of the gap's far side and the back showed through. An
// occluder whose projection of x's radius reaches this many levels beyond x's own (2^0.35,
// 1.27 times as many pixels) extends the walk to it; one barely nearer is the same surface
// curving towards the eye, or the edge of an object just in front, and extending there hid a
// band of the sculpture's bowl beside its ring (0.25: -0.02 dB; 0.5 left a random sphere's
// back in 0.45 % of its pixels against 0.14 %; bench/README.md, "Hidden points behind a
// nearer surface's gaps").
const float kNearerOccluderLevels = 0.35;

// Before the walk, the nearest depth in the 3x3 texels this many levels above its last one: a
// surface in front whose points lie farther apart on screen than x's radius reaches (a close-up,
// the eye a centimetre from a scan's flank) is never seen by the walk, so the rule above never
// fires, and the back showed through in blocks (the bunny's range scans 6 cm from its centre:
// 16 % of the pixels). Where that depth is so much nearer that x's radius projected there
// reaches kNearSurfaceThresholdLevels beyond the walk's own last level (4 times nearer, where
// that level is not clamped), the walk starts out to that level; its occluders are then asked
// on that level, whose radius spans the near surface's gaps. A surface only 2 times nearer is
// often an object beside x rather than over it, and walking that far beside it cost the
// station's views 0.016 dB (bench/README.md, "Hidden points behind a close-up's sparse front").
const uint kNearSurfaceProbeLevels = 2u;
const float kNearSurfaceThresholdLevels = 2.0;

/// The level the walk must reach for a surface near x but much nearer the eye (above); 0 where
/// the nearest depth in the probe's texels is not. x's own texel holds x, so that depth is finite.
float nearSurfaceLevel(ivec2 pixel, float radius, float maxLevel) {
    uint probe = min(uint(maxLevel) + kNearSurfaceProbeLevels, levelCount() - 1u);
    LevelLayout place = levelLayout(probe);
    float nearest = kInfinity;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 texel = clamp((pixel >> probe) + ivec2(dx, dy), ivec2(0), place.size - 1);
            nearest = min(nearest, texelFetch(minDepthTexels, int(texelIndex(place, texel))).r);
        }
    }
    float level = levelForRadius(radius, nearest);
    return level >= maxLevel + kNearSurfaceThresholdLevels ? level : 0.0;
}

bool visibleAt(ivec2 pixel, float depth) {
    vec3 x = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toCamera = towardsEye(x);
    float radius = surface.visibility.x * min(imageLoad(inColor, pixel).a, 1.0);
    float maxLevel = clamp(levelForRadius(radius, depth), 0.0,
                           float(levelCount() - 1u));
    uint levels =
        uint(clamp(max(maxLevel, nearSurfaceLevel(pixel, radius, maxLevel)), 0.0,
                   float(levelCount() - 1u)));
    float tau = surface.visibility.y;
    bool localSpacing = surface.spacing.x > 0.5;

    // Level by level, the 8 directions inside: one loop whose length differs between lanes
    // instead of eight (on llvmpipe each such loop costs beyond its steps). Branch-free: lanes
    // in lock-step all take every step anyway. A missing neighbour gives +inf, and a direction
    // without any counts as open sideways (omega = 1).
    float omega[8];
    uint seen[8];
    for (int k = 0; k < 8; ++k) {
        omega[k] = kInfinity;
        seen[k] = 0u;
    }
    LevelLayout place = levelLayout(0u);
    for (uint level = 0u; level <= levels; ++level, place = nextLevel(place)) {
        // The walk's last level so far asks whether an occluding neighbour calls for going on
        // (once per level reached: the coarsest texels hold the nearest points around).
        bool askOccluders = level == levels;
        for (int k = 0; k < 8; ++k) {
            ivec2 texel = (pixel >> level) + kDirections[k];
            bool withinImage = all(greaterThanEqual(texel, ivec2(0))) &&
                               all(lessThanEqual((texel + 1) << level, imageSizeOfFrame()));
            seen[k] += withinImage ? 1u : 0u;
            float neighbourDepth = texelFetch(
                minDepthTexels, int(texelIndex(place, clamp(texel, ivec2(0), place.size - 1)))).r;
            vec3 y = viewPositionAt(texelCentre(level, texel), neighbourDepth);
            float value = 1.0 - dot(normalize(y - x), toCamera);
            omega[k] = withinImage && !isinf(neighbourDepth) ? min(omega[k], value) : omega[k];
            if (askOccluders && withinImage && !isinf(neighbourDepth) && value < tau) {
                // Where the occluder is clearly nearer, the walk goes on until x's radius spans
                // its gaps at its depth (kNearerOccluderLevels says why only there).
                float nearerLevel = levelForRadius(radius, neighbourDepth);
                float occluderLevel =
                    nearerLevel >= maxLevel + kNearerOccluderLevels ? nearerLevel : 0.0;
                if (localSpacing) {
                    // And until it spans two of the occluder's expected gaps.
                    uint index = texelIndex(place, texel);
                    float occluderSpacing = texelFetch(frontSpacingTexels, int(index)).r;
                    occluderLevel = max(occluderLevel, levelForRadius(2.0 * surface.fill.x *
                                                                          occluderSpacing,
                                                                      neighbourDepth));
                }
                levels = max(levels, uint(clamp(occluderLevel, 0.0, float(levelCount() - 1u))));
            }
        }
    }
    bool complete[8];
    float weightedSum = 0.0;
    float weightSum = 0.0;
    for (int k = 0; k < 8; ++k) {
        omega[k] = isinf(omega[k]) ? 1.0 : omega[k];
        complete[k] = seen[k] == levels + 1u;
        float weight = float(seen[k]) / float(levels + 1u);
        weightedSum += weight * omega[k];
        weightSum += weight;
    }
    bool visible = weightedSum >= tau * weightSum;
    if (!visible && surface.visibility.z > 0.5) {
        int open = 0;
        bool occludes[8];
        for (int k = 0; k < 8; ++k) {
            open += complete[k] && omega[k] >= tau ? 1 : 0;
            occludes[k] = complete[k] && omega[k] < tau;
        }
        bool run = false;
        for (int k = 0; k < 8; ++k) {
            run = run || (occludes[k] && occludes[(k + 1) % 8] && occludes[(k + 2) % 8]);
        }
        visible = run && open >= 3;
    }
    return visible;
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        occupiedCount = 0u;
    }
    barrier();
    ivec2 pixel = dispatchTexel();
    if (insideLevel(0u, pixel) && insideRegion(pixel)) {
        if (isinf(texelFetch(minDepthTexels, int(texelIndex(0u, pixel))).r)) {
            imageStore(outVisibility, pixel, vec4(0.0));
        } else {
            occupied[atomicAdd(occupiedCount, 1u)] = gl_LocalInvocationIndex;
        }
    }
    barrier();
    if (gl_LocalInvocationIndex < occupiedCount) {
        uint local = occupied[gl_LocalInvocationIndex];
        ivec2 target = pixel - ivec2(gl_LocalInvocationID.xy) +
                       ivec2(local % gl_WorkGroupSize.x, local / gl_WorkGroupSize.x);
        bool visible =
            visibleAt(target, texelFetch(minDepthTexels, int(texelIndex(0u, target))).r);
        imageStore(outVisibility, target, vec4(visible ? 1.0 : 0.0));
    }
}
