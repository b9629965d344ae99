// Fill removal's per-direction reach and its per-pixel test, for FillRemoval.comp and
// FinishSurface.comp (which tests level 0 itself).
#include "render/PullPush.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_FILL_REACH) uniform usamplerBuffer fillReachTexels;

const uint kNoReach = 15u;

/// Beyond the image counts as weighted: a surface that reaches the image's border goes on past
/// it, and would otherwise lose its outermost pixels (a frame of background around close-ups).
bool weighted(uint onLevel, ivec2 texel) {
    return !insideLevel(onLevel, texel) || pullWeightAt(texelIndex(onLevel, texel)) > 0.0;
}

/// Per direction, `onLevel` where the neighbour of `texel` on that level has weight, else the
/// parent's answer (levels above `onLevel`).
uint reachOf(uint onLevel, ivec2 texel) {
    uint parent = onLevel + 1u < levelCount()
                      ? texelFetch(fillReachTexels, int(texelIndex(onLevel + 1u, texel >> 1))).r
                      : kNoReach * 0x11111111u;
    uint reach = 0u;
    for (int k = 0; k < 8; ++k) {
        uint nearest = weighted(onLevel, texel + kDirections[k]) ? onLevel
                                                                 : (parent >> (4 * k)) & 0xFu;
        reach |= nearest << (4 * k);
    }
    return reach;
}

/// Whether `pixel`, filled to `depth` by pull-push, belongs to the surface (the "mask").
/// `spacingRatio`: spacingRatioAt(pixel), which scales the expected gap.
bool onSurface(ivec2 pixel, float depth, float spacingRatio) {
    if (!(depth > 0.0 && !isinf(depth) && !isnan(depth))) {
        return false;
    }
    if (pullWeightAt(texelIndex(0u, pixel)) > 0.0) {
        return true;
    }
    // Level 1 at least: its texels bridge one-pixel gaps between dense points.
    uint levels = uint(
        ceil(clamp(levelForRadius(surface.fill.x * spacingRatio, depth), 1.0, float(levelCount() - 1u))));
    // kNoReach never counts: it could only mean the top level, whose one texel has no
    // neighbours.
    levels = min(levels, kNoReach - 1u);
    uint reach = reachOf(0u, pixel);
    int enclosed = 0;
    for (int k = 0; k < 8; ++k) {
        enclosed += ((reach >> (4 * k)) & 0xFu) <= levels ? 1 : 0;
    }
    return float(enclosed) >= surface.fill.y;
}
