#version 450
// Min-depth pyramid (paper Fig. 3): level 0 is the rasterized depth, a texel of level R the
// minimum of its 2x2 children on level R-1 (children past an odd edge simply do not exist).
// Levels from 1 on also record where in a texel its points lie ("pointCentroids": the mean of
// the children's that hold points; on level 1 the pixels' centres), for fill removal's
// outline (FillRemoval.glsl's sparseEnclosure). Children count alike, not by their points:
// any such mean lies inside the points' convex hull, which is all the outline needs. With the
// local spacing, every level also records the spacing ratio of its nearest points
// ("frontSpacing", level 0 from the "color" image's alpha), for hidden point removal.
//   STAGE_FIRST   levels 0 (a copy of the "depth" image) and 1 at once, one invocation per
//                 level-1 texel: a quarter of the invocations of a separate copy
//   STAGE_REDUCE  level `level` from level `level` - 1
//   STAGE_BOUNDS  the bounds of the texels of level `level` that hold a depth (min x, min y,
//                 max x, max y): a coarse level keeps the atomics few
#include "shared/pyramid.glsl"
#include "shared/region.glsl"
#include "shared/surface.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
layout(std430, binding = SUBSCAN_SSBO_PYRAMID) writeonly buffer Pyramid {
    float minDepth[];
};
layout(binding = SUBSCAN_TEXELS_PYRAMID) uniform samplerBuffer minDepthTexels;
layout(std430, binding = SUBSCAN_SSBO_POINT_CENTROIDS) writeonly buffer PointCentroids {
    uint pointCentroid[];
};
layout(binding = SUBSCAN_TEXELS_POINT_CENTROIDS) uniform usamplerBuffer pointCentroidTexels;
layout(std430, binding = SUBSCAN_SSBO_FRONT_SPACING) writeonly buffer FrontSpacing {
    float frontSpacing[];
};
layout(binding = SUBSCAN_TEXELS_FRONT_SPACING) uniform samplerBuffer frontSpacingTexels;
const float kFrontTolerance = 1.0e-4;
#if STAGE_FIRST
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inColor;
#endif
#if STAGE_BOUNDS
layout(std430, binding = SUBSCAN_SSBO_POINT_BOUNDS) buffer PointBounds {
    ivec4 pointBounds;
};
#endif

void main() {
    ivec2 texel = dispatchTexel();
#if STAGE_FIRST
    // A one-pixel image has no level 1 but still needs its level 0.
    if (any(greaterThanEqual(2 * texel, levelSize(0u))) || !insideRegion(texel)) {
        return;
    }
#else
    if (!insideLevel(level, texel) || !insideRegion(texel)) {
        return;
    }
#endif
#if STAGE_BOUNDS
    if (!isinf(texelFetch(minDepthTexels, int(texelIndex(level, texel))).r)) {
        atomicMin(pointBounds.x, texel.x);
        atomicMin(pointBounds.y, texel.y);
        atomicMax(pointBounds.z, texel.x);
        atomicMax(pointBounds.w, texel.y);
    }
#else
    float nearest = kInfinity;
    bool localSpacing = surface.spacing.x > 0.5;
    float childDepths[4];
    float childSpacings[4];
    vec2 centroidSum = vec2(0.0);  // in units of a texel of `level - 1`
    float occupiedChildren = 0.0;
    for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 child = 2 * texel + ivec2(dx, dy);
            if (insideLevel(level - 1u, child)) {
                uint childIndex = texelIndex(level - 1u, child);
#if STAGE_FIRST
                float depth = imageLoad(inDepth, child).r;
                minDepth[childIndex] = depth;
                vec2 inChild = vec2(0.5);
                float spacing = localSpacing ? imageLoad(inColor, child).a : 1.0;
                if (localSpacing) {
                    frontSpacing[childIndex] = spacing;
                }
#else
                float depth = texelFetch(minDepthTexels, int(childIndex)).r;
                float spacing =
                    localSpacing ? texelFetch(frontSpacingTexels, int(childIndex)).r : 1.0;
                vec2 inChild = isinf(depth)
                                   ? vec2(0.0)
                                   : unpackUnorm2x16(texelFetch(pointCentroidTexels,
                                                                int(childIndex)).r);
#endif
                nearest = min(nearest, depth);
                childDepths[2 * dy + dx] = depth;
                childSpacings[2 * dy + dx] = spacing;
                if (!isinf(depth)) {
                    centroidSum += vec2(child - 2 * texel) + inChild;
                    occupiedChildren += 1.0;
                }
            } else {
                childDepths[2 * dy + dx] = kInfinity;
                childSpacings[2 * dy + dx] = 1.0;
            }
        }
    }
    if (level < levelCount()) {
        uint index = texelIndex(level, texel);
        minDepth[index] = nearest;
        if (localSpacing) {
            // The sparsest of the children at the nearest depth, within a relative 1e-4: the
            // same points about another origin differ by about 1e-7 of their depth, and the
            // nearest of two such would pick either one's spacing.
            float sparsest = 1.0;
            for (int c = 0; c < 4; ++c) {
                sparsest = childDepths[c] <= nearest * (1.0 + kFrontTolerance)
                               ? max(sparsest, childSpacings[c])
                               : sparsest;
            }
            frontSpacing[index] = sparsest;
        }
        if (occupiedChildren > 0.0) {
            pointCentroid[index] = packUnorm2x16(centroidSum / (2.0 * occupiedChildren));
        }
    }
#endif
}
