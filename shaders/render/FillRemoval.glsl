// Fill removal's per-direction reach and its per-pixel test, for FillRemoval.comp and
// FinishSurface.comp (which tests level 0 itself).
#include "render/PullPush.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_FILL_REACH) uniform usamplerBuffer fillReachTexels;
layout(binding = SUBSCAN_TEXELS_PYRAMID) uniform samplerBuffer minDepthTexels;

const uint kNoReach = 15u;

/// Beyond the image counts as weighted: a surface that reaches the image's border goes on past
/// it, and would otherwise lose its outermost pixels (a frame of background around close-ups).
/// From level 1 on, a texel holding any point counts too, hidden ones included (the min-depth
/// pyramid is finite there): beside a near surface's edge, hidden point removal hides a band
/// of the far surface, and where that band was wider than a pixel the gaps in it found too
/// few directions enclosed and showed the background (the bunny's vertices at 512x512: holes
/// where one ear crosses the other and beside the feet). A hidden point lies behind a
/// surface or on one the test took for hidden, so in either case a surface covers its own
/// texel; the directions still do not compare depths, so a far structure thinner than the
/// band (a wire beside a building's edge) could close the background between it and the edge.
/// Level 0 keeps to the visible points: there the mask reads 8 neighbours a pixel, where 8
/// more loads (of the sub-pixel cells) cost FillRemoval +50 % and more on llvmpipe; the levels
/// above are a quarter of the pixels and less.
bool weighted(uint onLevel, ivec2 texel) {
    return !insideLevel(onLevel, texel) || pullWeightAt(texelIndex(onLevel, texel)) > 0.0 ||
           (onLevel > 0u &&
            !isinf(texelFetch(minDepthTexels, int(texelIndex(onLevel, texel))).r));
}

/// Per direction, `onLevel` where the neighbour of `texel` on that level is weighted, else the
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

layout(std430, binding = SUBSCAN_SSBO_OCCUPANCY) readonly buffer Occupancy {
    uint occupancy[];
};

/// Whether the pixel `pixel` without a visible point of its own, at depth `depth`, lies in a
/// gap the fill closes: enough directions find points within the expected gap.
bool fillsGap(ivec2 pixel, float depth, float spacingRatio) {
    // Level 1 at least: its texels bridge one-pixel gaps between dense points.
    uint levels = uint(ceil(
        clamp(levelForRadius(surface.fill.x * spacingRatio, depth), 1.0, float(levelCount() - 1u))));
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

/// How many of the 4x4 sub-cells of `pixel` hold a point (hidden ones too).
uint occupiedCells(ivec2 pixel) {
    return uint(bitCount(occupancy[uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x)]));
}

/// Whether `pixel`, holding a visible point, lies on the outline of the cloud with its centre
/// outside it. A straight outline leaves more than half of a pixel inside exactly when
/// it passes the centre; the points' cells show that area plus the cells the outline cuts,
/// half a column of them on average (1/8 of a pixel): so the centre lies outside when at most
/// 1/2 + 1/8 of the densest neighbour's cells hold points. Only beside a pixel without any
/// point that the fill leaves empty (the background: an outline, not a gap between points),
/// and only where the densest neighbour holds points in 3 cells or more: with 2, one cell more
/// or less is half of the count, noise rather than area. Sparse clouds show the area less
/// exactly (a cell holds one point or several alike), yet the rule still moves their outlines
/// closer to the truth (docs/eval.md, "Measured quality").
bool centreBeyondOutline(ivec2 pixel, float depth, float spacingRatio) {
    // The 4-neighbours without points first: off the outline (nearly every pixel) none is, and
    // the counts and the fill's reach below are skipped (llvmpipe skips a loop only where
    // none of its lanes enters it). Off the image's border the surface goes on.
    uint emptyBeside = 0u;  // bit k / 2 for the 4-neighbour k
    for (int k = 0; k < 8; k += 2) {
        ivec2 neighbour = pixel + kDirections[k];
        if (insideLevel(0u, neighbour) && occupiedCells(neighbour) == 0u) {
            emptyBeside |= 1u << (k / 2);
        }
    }
    if (emptyBeside == 0u) {
        return false;
    }
    uint own = occupiedCells(pixel);
    uint densest = own;
    for (int k = 0; k < 8; ++k) {
        ivec2 neighbour = pixel + kDirections[k];
        if (insideLevel(0u, neighbour)) {
            densest = max(densest, occupiedCells(neighbour));
        }
    }
    if (densest < 3u || float(own) > 0.625 * float(densest)) {
        return false;
    }
    // The neighbour's gap is judged at this pixel's depth.
    for (int k = 0; k < 8; k += 2) {
        if ((emptyBeside & (1u << (k / 2))) != 0u &&
            !fillsGap(pixel + kDirections[k], depth, spacingRatio)) {
            return true;
        }
    }
    return false;
}

/// Whether `pixel`, filled to `depth` by pull-push, belongs to the surface (the "mask").
/// `spacingRatio`: spacingRatioAt(pixel), which scales the expected gap.
bool onSurface(ivec2 pixel, float depth, float spacingRatio) {
    if (!(depth > 0.0 && !isinf(depth) && !isnan(depth))) {
        return false;
    }
    // A pixel whose points the hidden-point test all removed still shows a surface: its
    // points' own where the test erred (beside a near surface's edge it hides a band of the
    // far one, wider than the fill closes), else the one in front of them. So its cells place
    // the outline as a visible point's do (the cells are known only with the sub-pixel rule).
    bool holdsPoints = pullWeightAt(texelIndex(0u, pixel)) > 0.0 ||
                       (surface.fill.w != 0.0 && occupiedCells(pixel) > 0u);
    if (holdsPoints) {
        return surface.fill.w == 0.0 || !centreBeyondOutline(pixel, depth, spacingRatio);
    }
    return fillsGap(pixel, depth, spacingRatio);
}
