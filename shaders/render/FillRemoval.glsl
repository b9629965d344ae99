// Fill removal's per-direction reach and its per-pixel test, for FillRemoval.comp and
// FinishSurface.comp (which tests level 0 itself).
#include "render/PullPush.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_FILL_REACH) uniform usamplerBuffer fillReachTexels;
layout(binding = SUBSCAN_TEXELS_PYRAMID) uniform samplerBuffer minDepthTexels;
layout(binding = SUBSCAN_TEXELS_POINT_CENTROIDS) uniform usamplerBuffer pointCentroidTexels;
layout(binding = SUBSCAN_TEXELS_FILL_SPARSE) uniform usamplerBuffer fillSparseTexels;

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

/// Whether `texel` of `onLevel` (>= 1, laid out as `place`) lies in the image and holds
/// points; `offset`: their mean position (meanPointPosition) less `centre`.
bool pointsOf(uint onLevel, LevelLayout place, ivec2 texel, vec2 centre, out vec2 offset) {
    offset = vec2(0.0);
    if (!insideLevel(place, texel)) {
        return false;
    }
    uint index = texelIndex(place, texel);
    if (isinf(texelFetch(minDepthTexels, int(index)).r)) {
        return false;
    }
    offset = meanPointPosition(onLevel, texel, index) - centre;
    return true;
}

/// Whether the points of `texel` on `onLevel` (>= 2, at `index`) may enclose a gap on that
/// level by their own spacing: the level is at most one beyond their own expected gap's, as
/// sparseEnclosure's search is for the pixel's. A pixel in a gap takes the spacing of the finest
/// texel above it that holds points, which over sparse ground is a coarse one: where it held
/// one stray point far from the rest (a return beside a river, a scan's fringe), every pixel of
/// that texel searched as far as that point's spacing said, found the ground around it in
/// every direction, and the texel filled as one square (`render lone_star.laz --mode surface
/// --yaw 30 --pitch 35`). The ratio is the pull's: the kernel-weighted mean of the visible
/// points' in and beside the texel. Texels it gives no weight (hidden points only, away from
/// visible ones) count as they are.
bool enclosesOnItsOwnGap(uint onLevel, uint index) {
    if (surface.spacing.x < 0.5) {
        return true;
    }
    vec2 pulled = texelFetch(pullWeightTexels, int(index)).rg;
    if (!(pulled.x > 0.0)) {
        return true;
    }
    float ratio = max(pulled.y / pulled.x, 1.0);
    float ownGapLevel =
        levelForRadius(surface.fill.x * ratio, texelFetch(minDepthTexels, int(index)).r);
    return float(onLevel) <= ceil(max(ownGapLevel, 1.0)) + 1.0;
}

/// Whether the 3x3 texels of `onLevel` (>= 1, laid out as `place`) around the one holding
/// `centre` hold a point within `radius` pixels of it, judged by each texel's mean position.
bool pointWithinOn(uint onLevel, LevelLayout place, vec2 centre, float radius) {
    ivec2 middle = ivec2(centre) >> onLevel;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec2 offset;
            if (pointsOf(onLevel, place, middle + ivec2(dx, dy), centre, offset) &&
                dot(offset, offset) <= radius * radius) {
                return true;
            }
        }
    }
    return false;
}

/// Whether a point lies within `radius` (>= 1) pixels of `centre`. The texels of the level
/// that spans the radius reach it from anywhere in the centre's own texel, but their mean
/// positions lie up to a radius apart along a row of points, which leaves scallops between
/// them; the level below, twice as dense, fills those in where it reaches. A mean lies no
/// nearer than the nearest of its points, so the test errs towards "no". Levels from 1 on:
/// the radius is measured from a level-1 texel's centre, half a pixel from its pixels'.
bool pointWithin(vec2 centre, float radius) {
    uint coarse = clamp(uint(ceil(log2(radius))), 1u, levelCount() - 1u);
    uint fine = max(coarse - 1u, 1u);
    LevelLayout finePlace = levelLayout(fine);
    return pointWithinOn(fine, finePlace, centre, radius) ||
           (coarse > fine && pointWithinOn(coarse, nextLevel(finePlace), centre, radius));
}

/// Whether a point lies within `radius` (>= 1) pixels of `centre` along the axis `across`
/// (unit), and beside that axis by no more than the texels it is judged by: a surface seen as
/// scan lines goes on beyond its outermost line across the lines, not along them past their
/// ends (where a line ends, its own points show where the surface ends). The walk steps along
/// both halves of the axis, in three lanes a texel apart, by texels of about a quarter of the
/// radius but at least half the gap between the points along their lines (`alongGap`, in
/// pixels), so that one of a line's points falls beside the axis within the tolerance.
bool pointAcrossWithin(vec2 centre, float radius, vec2 across, float alongGap) {
    float level = round(log2(max(radius * 0.25, alongGap * 0.5)));
    uint onLevel = uint(clamp(level, 1.0, float(levelCount() - 1u)));
    float step = float(1u << onLevel);
    vec2 beside = vec2(-across.y, across.x);
    LevelLayout place = levelLayout(onLevel);
    // A step past the radius: the texel the walk's end lies in may hold points within it.
    // No farther than the image's diagonal (ratios reach 6e4 near the eye).
    float end = min(radius, length(vec2(pyramid.levels[0].yz))) + step;
    for (float t = 0.0; t <= end; t += step) {
        for (int lane = 0; lane < 6; ++lane) {
            vec2 position = centre + float(lane % 2 * 2 - 1) * t * across +
                            float(lane / 2 - 1) * step * beside;
            vec2 offset;
            if (!pointsOf(onLevel, place, ivec2(floor(position)) >> onLevel, centre, offset)) {
                continue;
            }
            float along = dot(offset, across);
            if (abs(along) <= radius && length(offset - along * across) <= 1.5 * step) {
                return true;
            }
        }
    }
    return false;
}

/// Beyond its outermost points a sparse surface is kept for this share of the expected gap,
/// times 1 - 1 / (local spacing ratio). The surface a row of samples saw ends somewhere before
/// the next row, which missed it: half a gap further on average, so stopping at the last row
/// loses a band along every sparse outline (a far wall's top row below its roof, a station's
/// last ring before the ground's edge). Where the points lie on scan lines, only across them
/// (pointAcrossWithin): reaching every way, past the lines' ends too, the fill ran in round
/// blobs over the ground's edges where a station's rings cross them. Measured on the virtual
/// station at 1024x1024, 4 views (near it / from the orbit; coverage, leakage, PSNR), the
/// passes' region taking the reach in (MinDepthPyramidPass): across the lines 0.625 gave
/// 0.955, 0.014 from the orbit; 0.75 0.992, 0.004, 27.7 dB / 0.979, 0.023, 21.5 dB; 0.875
/// 0.986, 0.031 from the orbit; every way, 0.75 gave 0.987, 0.056 from the orbit (and 0.977,
/// 0.044 while the region cut it). Points as dense as the cloud's own spacing (ratio 1: every
/// object scan) keep their outline where the sub-pixel rule puts it: a closed object's
/// outermost points lie at its silhouette, foreshortened, not a gap before it (the share
/// alone, unscaled, fattened the bunny's vertices at 512x512 from leakage 0.005 to 0.037).
const float kBeyondOutermostPoints = SUBSCAN_BEYOND_OUTERMOST_POINTS;

/// How far the image's border lies from `position` along `direction` (one of kDirections): to
/// the nearer of the borders it meets, across that border.
float toBorderAlong(vec2 position, vec2 direction) {
    vec2 size = vec2(pyramid.levels[0].yz);
    vec2 toBorders = mix(position, size - position, greaterThan(direction, vec2(0.0)));
    return min(direction.x != 0.0 ? toBorders.x : kInfinity,
               direction.y != 0.0 ? toBorders.y : kInfinity);
}

/// The directions among `open` whose image border the points of the texel at `index` reach,
/// seen from `centre` (sparseEnclosure's): their mean, `offset` from the centre, lies within one
/// `gap` (in pixels) of that border, plus half a `texelSize` (a mean lies up to that far inside
/// the texel's points), within SUBSCAN_BORDER_POINTS_CONE_DEGREES of the direction (its half of
/// the plane, less the band along the dividing line), and not behind the centre's `depth` by
/// more than the pull keeps (surface.fill.z pixel widths per pixel of the offset): a near
/// surface reaching the border does not let a far one behind the gap close it (a bunny's back
/// against its ear at a close-up). A surface that runs off the image goes on beyond it, so such
/// a direction is enclosed; with the border counted within two gaps only, holes showed above
/// the bottom border of ground seen at a slant, where the rows lie closer on screen than the
/// points along them and the points below a gap lie beside its downward cone (a jittered grid
/// plane at 320x240, 27 views: 324 hole pixels, now 10; Autzen's ground alike).
uint bordersReached(vec2 centre, vec2 offset, uint open, float gap, float texelSize, float depth,
                    uint index) {
    if (open == 0u) {
        return 0u;
    }
    float behind = texelFetch(minDepthTexels, int(index)).r - depth;
    if (behind > surface.fill.z * length(offset) * projectiveDepth(depth) / frame.depthRange.z) {
        return 0u;
    }
    const float cone = cos(radians(SUBSCAN_BORDER_POINTS_CONE_DEGREES));
    uint reached = 0u;
    for (int k = 0; k < 8; ++k) {
        vec2 direction = vec2(kDirections[k]);
        if ((open & (1u << k)) != 0u &&
            toBorderAlong(centre + offset, direction) <= gap + 0.5 * texelSize &&
            dot(offset, direction) >= cone * length(offset) * length(direction)) {
            reached |= 1u << k;
        }
    }
    return reached;
}

/// sparseEnclosure's near cones are 44 degrees wide, not 45: a mean (nearly) on a direction
/// encloses that one alone, not also the two at exactly 45 degrees, which float rounding would
/// decide either way.
const float kConeMargin = 1.0 / 45.0;

/// What the level-1 texel `texel` (whose reach is `reach`) adds to its pixels' gap test
/// (fillsGap), judged from its centre at its own complete depth and spacing ratio: bit k for
/// direction k, enclosed by points on some level from 2 up to one beyond the expected gap's;
/// bit 8 where a point lies within kBeyondOutermostPoints of the gap. A level's points enclose
/// a direction where the mean position of a texel's points (MinDepthPyramid.comp) lies within
/// 1.5 of the level's texels of the centre and within 44 degrees of the direction (each mean so
/// encloses the directions on either side of it), or within 2 texels and 22.5 degrees (the
/// direction nearest it). Eight such cones leave one wholly on the far side of any straight
/// line through the centre (an open half-plane holds a direction within 22.5 degrees of its
/// normal, and 22.5 + 44 < 90), so nothing beyond a straight outline fills: the fill stays
/// inside the points' convex hull. The distance, measured from the centre over the 5x5 texels
/// around its own, makes the filled region's outline follow the points: the rule before looked
/// at the 8 texels beside the centre's own, the same for every pixel of it, and sparse surfaces
/// ended in squares of coarse texels. The far, narrow cones reach the next row of a plane seen
/// at a grazing angle, whose rows lie farther apart on screen than its spacing says
/// (StreamedSurfaceGLTest); wide ones that far fill a sculpture's notches (leakage 0.0062 ->
/// 0.0080; docs/pipeline.md). Once per level-1 texel instead of per pixel: on llvmpipe, where
/// every lane of a group runs a loop any of them enters, the walk over levels per pixel took
/// FillRemoval from 19.7 to 45.8 ms at 1920x1080 (the Happy Buddha). Its pixels lie within 0.71
/// pixels of the centre.
uint sparseEnclosure(ivec2 texel, uint reach) {
    uint index = texelIndex(1u, texel);
    float depth = pushValueAt(index).x;
    if (!(depth > 0.0 && !isinf(depth))) {
        return 0u;
    }
    // A pixel in a gap takes the ratio of the finest texel above it that holds visible
    // points (spacingRatioAt), which is the level-1 texel's (spacingRatioFrom level 1).
    float spacingRatio = spacingRatioFrom(1u, texel);
    float gapLevel = levelForRadius(surface.fill.x * spacingRatio, depth);
    // One level more than the gap's (at least 1: its texels bridge one-pixel gaps between
    // dense points): a texel on the gap's level beside the pixel's own holds a point of the
    // next row only where the rows fall that way (without it coverage fell to 0.97 on the
    // bunny's vertices at 512x512, 0.95 near the station); the cones keep the coarser level
    // from reaching past the outline. kNoReach never counts: it could only mean the top level.
    uint levels = min(uint(ceil(clamp(gapLevel, 1.0, float(levelCount() - 1u)))) + 1u,
                      min(kNoReach - 1u, levelCount() - 1u));
    // Twice the gap: the points that enclose a pixel lie up to about that far (the level
    // beyond the gap's), and a pixel 1.5 pixels from the border between points 2.2 pixels
    // apart must still count it (SurfaceCloseUpGLTest). Beyond the image the surface goes on.
    // Farther, up to SUBSCAN_BORDER_POINTS_REACH gaps, where points reach it (bordersReached).
    float gap = exp2(gapLevel);
    float borderReach = 2.0 * gap;
    vec2 centre = (vec2(texel) + 0.5) * 2.0;
    // Directions its pixels find on levels 0 and 1 (a neighbour on level 1 is weighted) need
    // nothing more; the walk starts on the finest level weighted in a direction still open.
    uint enclosure = 0u;
    uint nearBorder = 0u;
    uint first = kNoReach;
    for (int k = 0; k < 8; ++k) {
        vec2 direction = vec2(kDirections[k]);
        float distance = toBorderAlong(centre, direction) * length(direction);
        uint finest = (reach >> (4 * k)) & 0xFu;
        if (finest <= 1u || distance <= borderReach) {
            enclosure |= 1u << k;
        } else {
            first = min(first, finest);
            nearBorder |= distance <= SUBSCAN_BORDER_POINTS_REACH * gap ? 1u << k : 0u;
        }
    }
    first = max(first, 2u);
    LevelLayout place = levelLayout(min(first, levelCount() - 1u));
    for (uint l = first; l <= levels && enclosure != 0xFFu; ++l, place = nextLevel(place)) {
        float texelSize = float(1u << l);
        ivec2 corner = ivec2(centre / texelSize) - 2;
        for (int j = 0; j < 25; ++j) {
            ivec2 around = corner + ivec2(j % 5, j / 5);
            vec2 offset;
            // A mean at the centre has no direction (its 16-bit position in the texel would
            // give it one at random).
            if (!pointsOf(l, place, around, centre, offset) ||
                dot(offset, offset) > 4.0 * texelSize * texelSize ||
                dot(offset, offset) <= 1e-4 * texelSize * texelSize) {
                continue;
            }
            // In 45 degree sectors from direction 0 (kDirections turns by 45 each): the
            // directions on either side of the mean, each where it lies within its cone (44
            // degrees within 1.5 texels, 22.5 within 2).
            float sector = atan(offset.y, offset.x) * (4.0 / kPi) + 8.0;
            uint before = uint(sector) & 7u;
            uint after = (before + 1u) & 7u;
            float past = fract(sector);
            bool close = dot(offset, offset) <= 2.25 * texelSize * texelSize;
            float margin = close ? kConeMargin : 0.5;
            uint directions = (past < 1.0 - margin ? 1u << before : 0u) |
                              (past > margin ? 1u << after : 0u);
            uint index = texelIndex(place, around);
            directions |= bordersReached(centre, offset, nearBorder & ~enclosure, gap,
                                         texelSize, depth, index);
            if ((directions & ~enclosure) != 0u && enclosesOnItsOwnGap(l, index)) {
                enclosure |= directions;
            }
        }
    }
    // Under a pixel the sub-pixel outline rule places the outline.
    float beyond = kBeyondOutermostPoints * (1.0 - 1.0 / spacingRatio) * gap;
    if (beyond >= 1.0) {
        // Where the points' scan lines agree on an axis, only across them (pointAcrossWithin).
        // Its length, 1 - w / |across| (RasterizePoints.comp), above one half: the lines lie
        // more than twice as far apart as the points along them, which lie (1 - length) of
        // the expected gap apart.
        vec2 axis = acrossAxisFrom(1u, texel);
        float anisotropy = length(axis);
        bool near;
        if (anisotropy > 0.5) {
            float angle = 0.5 * atan(axis.y, axis.x);
            near = pointAcrossWithin(centre, beyond, vec2(cos(angle), sin(angle)),
                                     (1.0 - anisotropy) * gap);
        } else {
            near = pointWithin(centre, beyond);
        }
        if (near) {
            enclosure |= 1u << 8;
        }
    }
    return enclosure;
}

/// Where the level-1 texel `texel`'s word lies in "fillSparse", which holds level 1 alone.
uint fillSparseIndex(ivec2 texel) { return texelIndex(1u, texel) - levelLayout(1u).first; }

/// Whether the pixel `pixel` without a visible point of its own lies in a gap the fill closes:
/// enough directions find points within the expected gap, on levels 0 and 1 beside it
/// (a level-0 neighbour lies exactly in its direction, a level-1 texel within 3 pixels, so
/// it oversteps an outline by a pixel at most) or further on in their cones (its level-1
/// texel's sparseEnclosure); or a sparse surface's outermost points lie near enough.
bool fillsGap(ivec2 pixel) {
    uint reach = reachOf(0u, pixel);
    uint found = 0u;  // bit k: direction k enclosed
    for (int k = 0; k < 8; ++k) {
        found |= ((reach >> (4 * k)) & 0xFu) <= 1u ? 1u << k : 0u;
    }
    if (float(bitCount(found)) >= surface.fill.y) {
        return true;
    }
    if (levelCount() < 2u) {
        return false;
    }
    uint enclosure = texelFetch(fillSparseTexels, int(fillSparseIndex(pixel >> 1))).r;
    return float(bitCount(found | (enclosure & 0xFFu))) >= surface.fill.y ||
           (enclosure & (1u << 8)) != 0u;
}

/// How many of the 4x4 sub-cells of `pixel` hold a point (hidden ones too).
uint occupiedCells(ivec2 pixel) {
    return uint(bitCount(occupancy[uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x)]));
}

/// The share of `pixel` (holding points) that the cloud's outline leaves inside it, where the
/// pixel lies on the outline; else -1. A straight outline leaves more than half of a pixel
/// inside exactly when it passes the centre; the points' cells show the inside area plus the
/// cells the outline cuts, half a column of them on average (1/8 of a pixel): so the share is
/// the pixel's occupied cells against the densest neighbour's, less 1/8. Only beside a pixel
/// without any point that the fill leaves empty (the background: an outline, not a gap
/// between points), and only where the densest neighbour holds points in 3 cells or more: with
/// 2, one cell more or less is half of the count, noise rather than area. Sparse clouds show
/// the area less exactly (a cell holds one point or several alike), yet the rule still moves
/// their outlines closer to the truth (docs/eval.md, "Measured quality").
float outlineShare(ivec2 pixel) {
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
        return -1.0;
    }
    uint own = occupiedCells(pixel);
    uint densest = own;
    for (int k = 0; k < 8; ++k) {
        ivec2 neighbour = pixel + kDirections[k];
        if (insideLevel(0u, neighbour)) {
            densest = max(densest, occupiedCells(neighbour));
        }
    }
    if (densest < 3u) {
        return -1.0;
    }
    for (int k = 0; k < 8; k += 2) {
        if ((emptyBeside & (1u << (k / 2))) != 0u && !fillsGap(pixel + kDirections[k])) {
            return clamp(float(own) / float(densest) - 0.125, 0.0, 1.0);
        }
    }
    return -1.0;
}

/// How much of `pixel`, filled to `depth` by pull-push, the surface covers (the "mask"): 0 off
/// it, else 1, except on the sub-pixel outline, where a pixel is surface when more than half of
/// it lies inside (its centre does, on a straight outline) and is covered by that share (the
/// anti-aliased outline, pipeline.md). The pixels beyond the mask stay background though up to
/// half covered: shown with a neighbour's colour over their share, they made the converged and
/// the filtered pictures of every object scan worse (noisy points beyond an outline fill more
/// cells than the surface covers).
float surfaceCoverage(ivec2 pixel, float depth) {
    if (!(depth > 0.0 && !isinf(depth) && !isnan(depth))) {
        return 0.0;
    }
    // A pixel whose points the hidden-point test all removed still shows a surface: its
    // points' own where the test erred (beside a near surface's edge it hides a band of the
    // far one, wider than the fill closes), else the one in front of them. So its cells place
    // the outline as a visible point's do (the cells are known only with the sub-pixel rule).
    bool holdsPoints = pullWeightAt(texelIndex(0u, pixel)) > 0.0 ||
                       (surface.fill.w != 0.0 && occupiedCells(pixel) > 0u);
    if (!holdsPoints) {
        return fillsGap(pixel) ? 1.0 : 0.0;
    }
    float share = surface.fill.w != 0.0 ? outlineShare(pixel) : -1.0;
    return share < 0.0 ? 1.0 : (share > 0.5 ? share : 0.0);
}
