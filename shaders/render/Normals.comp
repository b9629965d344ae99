#version 450
// Normals from the filled depth (Bouchiba 2018): on every push level, back-project a texel and
// its neighbours, take per axis the tangent towards the neighbour with the smaller depth jump
// (so silhouettes do not bend normals), cross them and face the result to the camera. Where
// only one of the two neighbours is fully covered by points (pull weight 1), its side is taken
// instead: the other is fill, which continues the surface past its silhouette flatter than it
// is and made the rims of round objects face the camera (too bright under a head light). Each
// pixel then blends the normals of the two levels around its fractional smoothing level, and
// near the outline follows the surface's turn towards it (Normals.glsl).
//   STAGE_LEVEL  normals of level `level` into the normal pyramid
//   STAGE_BLEND  the per-pixel blend into the "normals" image (view space), unless
//                FinishSurface.comp blends level 0 itself
#define NORMALS_SEE_OUTLINE STAGE_BLEND
#include "render/Normals.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
// Written as a storage buffer, read as a buffer texture (see Buffer::bindTexels).
layout(std430, binding = SUBSCAN_SSBO_NORMALS) writeonly buffer Normals {
    vec4 normalPyramid[];
};
#if STAGE_BLEND
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outNormals;
#endif

#if STAGE_LEVEL
vec3 positionOf(ivec2 texel) {
    return viewPositionAt(texelCentre(level, texel),
                          pushValueAt(texelIndex(level, texel)).x);
}

bool fullyCovered(ivec2 texel) { return pullWeightAt(texelIndex(level, texel)) >= 1.0; }

/// The tangent along `axis`: towards the existing neighbour that points cover fully where only
/// one is, else towards the one with the smaller depth jump.
vec3 tangent(ivec2 texel, vec3 centre, ivec2 axis) {
    bool hasNext = insideLevel(level, texel + axis);
    bool hasPrevious = insideLevel(level, texel - axis);
    vec3 next = hasNext ? positionOf(texel + axis) - centre : vec3(0.0);
    vec3 previous = hasPrevious ? centre - positionOf(texel - axis) : vec3(0.0);
    if (!hasPrevious) {
        return next;
    }
    if (!hasNext) {
        return previous;
    }
    bool nextCovered = fullyCovered(texel + axis);
    if (nextCovered != fullyCovered(texel - axis)) {
        return nextCovered ? next : previous;
    }
    return abs(next.z) <= abs(previous.z) ? next : previous;
}
#endif

void main() {
    ivec2 texel = dispatchTexel();
#if STAGE_LEVEL
    if (!insideLevel(level, texel) || !insideRegion(texel)) {
        return;
    }
    vec3 centre = positionOf(texel);
    vec3 normal = cross(tangent(texel, centre, ivec2(1, 0)), tangent(texel, centre, ivec2(0, 1)));
    float length2 = dot(normal, normal);
    // Degenerate (a 1-texel level, or infinite depth): face the camera.
    normal = length2 > 0.0 && !isinf(length2) && !isnan(length2) ? normal * inversesqrt(length2)
                                                                  : towardsEye(centre);
    if (isnan(normal.x)) {
        normal = vec3(0.0, 0.0, 1.0);
    }
    if (dot(normal, towardsEye(centre)) < 0.0) {
        normal = -normal;
    }
    normalPyramid[texelIndex(level, texel)] = vec4(normal, 0.0);
#else
    if (!insideLevel(0u, texel) || !insideRegion(texel)) {
        return;
    }
    float depth = imageLoad(inSurfaceDepth, texel).r;
    if (isinf(depth)) {
        imageStore(outNormals, texel, vec4(0.0));
        return;
    }
    vec3 normal = blendedNormal(texel, depth, spacingRatioAt(texel));
    imageStore(outNormals, texel, vec4(normal, 1.0));
#endif
}
