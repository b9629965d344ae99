// Fill removal's per-direction reach and its per-pixel test, for FillRemoval.comp and
// FinishSurface.comp (which tests level 0 itself).
#include "render/PullPush.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_FILL_REACH) uniform usamplerBuffer fillReachTexels;
layout(binding = SUBSCAN_TEXELS_PYRAMID) uniform samplerBuffer minDepthTexels;
layout(binding = SUBSCAN_TEXELS_POINT_CENTROIDS) uniform usamplerBuffer pointCentroidTexels;

const uint kNoReach = 15u;

/// Beyond the image counts as weighted: a surface that reaches the image's border goes on past
/// it, and would otherwise lose its outermost pixels (a frame of background around close-ups).
/// From level 1 on, a texel counts where it holds any point, hidden ones included (the
/// min-depth pyramid is finite there), and only there: the pull weight, which the paper's
/// rule and this one read before, spreads half a texel beyond the points on every level (the
/// pull's 4x4 kernel), so on the expected gap's level a pixel up to a texel beyond a sparse
/// cloud's outline found "points" beside it, and the fill ran past the outline in blocks of
/// that level's texels (a station's far ground from above: leakage 0.09). Hidden points count
/// because beside a near surface's edge, hidden point removal hides a band of the far
/// surface, and where that band was wider than a pixel the gaps in it found too few
/// directions enclosed and showed the background (the bunny's vertices at 512x512: holes
/// where one ear crosses the other and beside the feet). A hidden point lies behind a
/// surface or on one the test took for hidden, so in either case a surface covers its own
/// texel; the directions still do not compare depths, so a far structure thinner than the
/// band (a wire beside a building's edge) could close the background between it and the edge.
/// Level 0 keeps to the visible points: there the mask reads 8 neighbours a pixel, where 8
/// more loads (of the sub-pixel cells) cost FillRemoval +50 % and more on llvmpipe; the levels
/// above are a quarter of the pixels and less.
bool weighted(uint onLevel, ivec2 texel) {
    if (!insideLevel(onLevel, texel)) {
        return true;
    }
    uint index = texelIndex(onLevel, texel);
    return onLevel == 0u ? pullWeightAt(index) > 0.0
                         : !isinf(texelFetch(minDepthTexels, int(index)).r);
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

/// Where the points of `texel` (at `index` on `onLevel` >= 1, holding points) lie on average,
/// in window coordinates (MinDepthPyramid.comp).
vec2 meanPointPosition(uint onLevel, ivec2 texel, uint index) {
    vec2 inTexel = unpackUnorm2x16(texelFetch(pointCentroidTexels, int(index)).r);
    return (vec2(texel) + inTexel) * float(1u << onLevel);
}

/// cos 67.5 degrees. Eight cones this wide around the directions leave one wholly on the far
/// side of any straight line through a pixel (each open half-plane holds a direction within
/// 22.5 degrees of its normal, and 22.5 + 67.5 = 90), so a pixel beyond a straight outline
/// finds no points in that direction; any narrower cone would turn away more true gaps.
const float kEnclosingConeCos = 0.38268343;

/// Whether the points of the texel beside `pixel`'s own on `onLevel`, in direction k (a
/// weighted texel), lie in that direction as seen from the pixel's centre: within the cone
/// above around it, judged by their mean position (MinDepthPyramid.comp). A coarse texel
/// beside the pixel's reaches up to 90 degrees to either side of the direction, so without
/// this a pixel beyond a sparse cloud's outline found points "around" it in texels that
/// hold them only on the cloud's side, and the fill ran past the outline in the coarse
/// texels' blocks. On level 0 the neighbour lies exactly in the direction. Beyond the image
/// the surface goes on, but counts only where the border lies within `borderReach` pixels:
/// a coarse level's texel beside the border reaches far into the picture (once the fill
/// looked a level beyond the gap's, the corners between a sphere's silhouette and the border
/// filled).
bool enclosesTowards(ivec2 pixel, int k, uint onLevel, float borderReach) {
    ivec2 texel = (pixel >> onLevel) + kDirections[k];
    if (onLevel == 0u) {
        return true;
    }
    vec2 centre = vec2(pixel) + 0.5;
    vec2 direction = vec2(kDirections[k]);
    if (!insideLevel(onLevel, texel)) {
        // How far along the direction the image ends.
        vec2 size = vec2(levelSize(0u));
        vec2 toBorder = mix(centre, size - centre, greaterThan(direction, vec2(0.0)));
        float distance = min(direction.x != 0.0 ? toBorder.x : kInfinity,
                             direction.y != 0.0 ? toBorder.y : kInfinity);
        return distance * length(direction) <= borderReach;
    }
    vec2 offset = meanPointPosition(onLevel, texel, texelIndex(onLevel, texel)) - centre;
    return dot(offset, direction) > kEnclosingConeCos * length(offset) * length(direction);
}

/// Whether the 3x3 texels of `onLevel` around `pixel`'s hold a point within `radius` pixels of
/// its centre, judged by each texel's mean point position.
bool pointWithinOn(uint onLevel, ivec2 pixel, float radius) {
    LevelLayout place = levelLayout(onLevel);
    ivec2 centre = pixel >> onLevel;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 texel = centre + ivec2(dx, dy);
            if (!insideLevel(place, texel)) {
                continue;
            }
            uint index = texelIndex(place, texel);
            if (isinf(texelFetch(minDepthTexels, int(index)).r)) {
                continue;
            }
            vec2 position =
                onLevel == 0u ? vec2(texel) + 0.5 : meanPointPosition(onLevel, texel, index);
            vec2 offset = position - (vec2(pixel) + 0.5);
            if (dot(offset, offset) <= radius * radius) {
                return true;
            }
        }
    }
    return false;
}

/// Whether a point lies within `radius` (>= 1) pixels of `pixel`'s centre. The texels of the
/// level that spans the radius reach it from anywhere in the pixel's own texel, but their mean
/// positions lie up to a radius apart along a row of points, which leaves scallops between
/// them; the level below, twice as dense, fills those in where it reaches. A mean lies no
/// nearer than the nearest of its points, so the test errs towards "no".
bool pointWithin(ivec2 pixel, float radius) {
    uint coarse = min(uint(ceil(log2(radius))), levelCount() - 1u);
    return (coarse > 0u && pointWithinOn(coarse - 1u, pixel, radius)) ||
           pointWithinOn(coarse, pixel, radius);
}

/// Beyond its outermost points a sparse surface is kept for this share of the expected gap,
/// times 1 - 1 / (local spacing ratio). The surface a row of samples saw ends somewhere before
/// the next row, which missed it: half a gap further on average, so stopping at the last row
/// loses a band along every sparse outline (a far wall's top row below its roof, a station's
/// last ring before the ground's edge). Measured on the virtual station at 1024x1024, 4 views
/// (near it / from the orbit; coverage, leakage, PSNR): 0.5 gave 0.988, 0.002, 26.2 dB /
/// 0.953, 0.017, 21.2 dB; 0.75 0.992, 0.004, 26.7 dB / 0.977, 0.044, 21.3 dB (the rule before,
/// the pull weight's blocks: 0.995, 0.005, 26.6 dB / 0.973, 0.089, 21.2 dB). The rows' gap
/// beside an outline is wider than the local spacing says, which a share above one half
/// makes up for. Points as dense as the cloud's own spacing (ratio
/// 1: every object scan) keep their outline where the sub-pixel rule puts it: a closed
/// object's outermost points lie at its silhouette, foreshortened, not a gap before it (the
/// share alone, unscaled, fattened the bunny's vertices at 512x512 from leakage 0.005 to 0.037).
const float kBeyondOutermostPoints = 0.75;

/// Whether the pixel `pixel` without a visible point of its own, at depth `depth`, lies in a
/// gap the fill closes: enough directions find points within the expected gap, in their
/// direction (enclosesTowards: the fill stays within the points' convex hull); or a sparse
/// surface's outermost points lie within kBeyondOutermostPoints of that gap.
bool fillsGap(ivec2 pixel, float depth, float spacingRatio) {
    float gapLevel = levelForRadius(surface.fill.x * spacingRatio, depth);
    // Level 1 at least: its texels bridge one-pixel gaps between dense points. One level more
    // than the gap's: a texel on the gap's level beside the pixel's own holds a point of the
    // next row only where the rows fall that way, which the pull weight's spread used to
    // paper over (without it coverage fell to 0.97 on the bunny's vertices at 512x512, 0.95
    // near the station); the cone keeps the coarser level from reaching past the outline.
    uint levels = uint(ceil(clamp(gapLevel, 1.0, float(levelCount() - 1u)))) + 1u;
    // kNoReach never counts: it could only mean the top level, whose one texel has no
    // neighbours.
    levels = min(levels, min(kNoReach - 1u, levelCount() - 1u));
    // Twice the gap: the points that enclose a pixel lie up to about that far (the level
    // beyond the gap's), and a pixel 1.5 pixels from the border between points 2.2 pixels
    // apart must still count it (SurfaceCloseUpGLTest).
    float borderReach = 2.0 * exp2(gapLevel);
    uint reach = reachOf(0u, pixel);
    // Directions with points on some level within reach, and of those the ones found on level
    // 0, which lie exactly in their direction: the cones are looked at only where these leave
    // the answer open (on llvmpipe the walk below doubled FillRemoval's time when every pixel
    // took it).
    int reachable = 0;
    int besides = 0;
    uint nearestLevel = kNoReach;
    for (int k = 0; k < 8; ++k) {
        uint finest = (reach >> (4 * k)) & 0xFu;
        reachable += finest <= levels ? 1 : 0;
        besides += finest == 0u ? 1 : 0;
        nearestLevel = min(nearestLevel, finest);
    }
    if (float(besides) >= surface.fill.y) {
        return true;
    }
    if (float(reachable) >= surface.fill.y) {
        int enclosed = 0;
        for (int k = 0; k < 8; ++k) {
            // The finest weighted level first (the reach), then coarser ones: the finest
            // texel's points may lie beside the direction where a coarser texel's do not.
            uint finest = (reach >> (4 * k)) & 0xFu;
            bool found = false;
            for (uint l = finest; l <= levels && !found; ++l) {
                found = (l == finest || weighted(l, (pixel >> l) + kDirections[k])) &&
                        enclosesTowards(pixel, k, l, borderReach);
            }
            enclosed += found ? 1 : 0;
        }
        if (float(enclosed) >= surface.fill.y) {
            return true;
        }
    }
    // Under a pixel the sub-pixel outline rule places the outline.
    float beyond = kBeyondOutermostPoints * (1.0 - 1.0 / max(spacingRatio, 1.0)) * exp2(gapLevel);
    if (beyond < 1.0) {
        return false;
    }
    // No point in the 3x3 texels around the pixel's on the radius's level, nor in that texel
    // itself, leaves none within the radius (pointWithin looks no further): the background
    // away from the cloud, most of the pixels that get here, skips the 18 texels.
    uint radiusLevel = uint(ceil(log2(beyond)));
    if (radiusLevel >= 1u && radiusLevel < levelCount() && nearestLevel > radiusLevel &&
        isinf(texelFetch(minDepthTexels, int(texelIndex(radiusLevel, pixel >> radiusLevel))).r)) {
        return false;
    }
    return pointWithin(pixel, beyond);
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
