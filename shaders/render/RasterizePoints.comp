#version 450
// Compute rasterization of 1-pixel points (Schuetz et al. 2021): per pixel keep the nearest
// point, ties broken by the smaller point index, so every path gives the same winner.
//   STAGE_DEPTH    one thread per point: 32-bit atomicMin of the depth bits, straight into the
//                  "depth" image (viewed as r32ui; cleared to +inf, whose bits are the largest)
//   STAGE_INDEX    one thread per point: among points at the winning depth, atomicMin of
//                  index, and with BLEND_COLORS or BLEND_NORMALS the blend's sums below
//   STAGE_INT64    one thread per point: one 64-bit atomicMin of depthBits << 32 | index
//                  (DEPTH and INT64 also mark the point's 4x4 sub-cell of its pixel, hidden or
//                  not, when the surface places its outline by them: surface.fill.w)
//   STAGE_BLEND    one thread per point, after INT64 (whose nearest is known only then): with
//                  BLEND_COLORS a point within the relative depth raster.colorBlend of its
//                  pixel's nearest adds its linear colour (fixed point) and 1 to the pixel's
//                  sums (Schuetz et al. 2021's high-quality shading); with BLEND_NORMALS one
//                  within raster.normalBlend pixel widths behind the nearest its view-space
//                  normal, facing the eye and weighted by its cosine towards it, to the
//                  pixel's normal sums
//   STAGE_RESOLVE  one thread per pixel of the cloud's projected bounding box: the winner's
//                  linear colour, or with BLEND_COLORS the mean of the sums (and with USE_INT64
//                  the winner's depth) into images cleared before; alpha: the winner's local
//                  spacing on screen in units of h's (1 without local spacing); with the
//                  points' own normals (SurfaceParams.normals.z) the winner's normal in view
//                  space, facing the eye, or with BLEND_NORMALS the normalised sum, into
//                  "pointNormals" (0 where it has none)
// Positive IEEE floats order like their bit patterns, so depth bits compare as uints. Points
// are read as buffer textures and the 32-bit path keeps its per-pixel words in images rather
// than storage buffers: on llvmpipe a texel fetch or image load is a vector gather, a storage
// buffer load one guarded scalar load per lane.
#if USE_INT64
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_NV_shader_atomic_int64 : require
#endif
#include "shared/common.glsl"
#include "shared/region.glsl"
#include "shared/surface.glsl"

layout(std140, binding = SUBSCAN_UBO_PASS) uniform RasterBlock {
    RasterParams raster;
};
layout(binding = SUBSCAN_TEXELS_POSITIONS) uniform samplerBuffer positions;  // x, y, z per point
layout(binding = SUBSCAN_TEXELS_COLORS) uniform usamplerBuffer colors;

/// Chunk point `local` in view space.
vec3 viewPositionOfPoint(uint local) {
    int first = 3 * int(local);
    vec3 position = vec3(texelFetch(positions, first).r, texelFetch(positions, first + 1).r,
                         texelFetch(positions, first + 2).r);
    return (frame.viewFromCloud * vec4(position, 1.0)).xyz;
}
#if STAGE_DEPTH
layout(binding = SUBSCAN_IMAGE_OUT0, r32ui) uniform uimage2D depthBits;
#elif STAGE_INDEX
layout(binding = SUBSCAN_IMAGE_IN0, r32ui) readonly uniform uimage2D depthBits;
layout(binding = SUBSCAN_IMAGE_OUT2, r32ui) uniform uimage2D pointIndex;
#elif STAGE_RESOLVE && !USE_INT64
layout(binding = SUBSCAN_IMAGE_IN0, r32ui) readonly uniform uimage2D pointIndex;
#endif
#if USE_INT64
layout(std430, binding = SUBSCAN_SSBO_DEPTH_INDEX) buffer DepthIndex {
    uint64_t depthIndex[];
};
#endif
#if STAGE_DEPTH || STAGE_INT64
layout(std430, binding = SUBSCAN_SSBO_OCCUPANCY) buffer Occupancy {
    uint occupancy[];
};
#endif
#if BLEND_COLORS
layout(std430, binding = SUBSCAN_SSBO_COLOR_SUMS) buffer ColorSums {
    uvec4 colorSums[];
};
#endif
#if BLEND_NORMALS
layout(std430, binding = SUBSCAN_SSBO_NORMAL_SUMS) buffer NormalSums {
    int normalSums[];  // x, y, z per pixel
};
#endif
#if BLEND_NORMALS || STAGE_RESOLVE
layout(binding = SUBSCAN_TEXELS_POINT_NORMALS) uniform usamplerBuffer pointNormals;

/// Chunk point `local`'s normal in view space, 0 for none. Its sign is arbitrary where no
/// sensor oriented it: the side seen is the side shaded, so users turn it to face the eye.
vec3 viewNormal(uint local) {
    return mat3(frame.viewFromCloud) * unpackNormal(texelFetch(pointNormals, int(local)).r);
}
#endif
#if STAGE_BLEND && !(USE_INT64 && (BLEND_COLORS || BLEND_NORMALS))
#error "STAGE_BLEND is the 64-bit path's sum pass: the 32-bit path sums in STAGE_INDEX"
#endif

#if STAGE_RESOLVE
layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
#if USE_INT64
layout(binding = SUBSCAN_IMAGE_OUT0, r32f) writeonly uniform image2D outDepth;
#endif
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outColor;
layout(binding = SUBSCAN_IMAGE_OUT2, rgba16f) writeonly uniform image2D outNormal;
layout(binding = SUBSCAN_TEXELS_LOCAL_SPACING) uniform samplerBuffer localSpacing;
layout(std430, binding = SUBSCAN_SSBO_ACROSS_LINES) writeonly buffer AcrossLines {
    uint acrossLines[];
};

/// The local spacing (estimateLocalSpacing) of chunk point `local` on screen, over h's there
/// (x): the larger of its spacing w and its vector across scan lines projected; and (yz) that
/// vector's axis as a doubled-angle vector where it is the larger (the direction a sparse
/// surface goes on beyond its outermost line: FillRemoval.glsl's pointAcrossWithin), of
/// length 1 - w / the vector's (how much sparser the lines lie than the points along them),
/// else 0. The projection is to first order (window = f xy / d at distance d: the offset a
/// moves it by f / d * (a.xy + xy * a.z / d)), which an across vector pointing behind the eye
/// cannot break.
vec3 spacingOnScreen(uint local) {
    vec3 viewPosition = viewPositionOfPoint(local);
    vec4 spacing = texelFetch(localSpacing, int(local));
    vec3 across = mat3(frame.viewFromCloud) * spacing.xyz;  // in units of h
    float distance = projectiveDepth(-viewPosition.z);
    vec2 moved = frame.depthRange.w > 0.0
                     ? across.xy
                     : across.xy + viewPosition.xy * (across.z / distance);
    // Both lengths in units of h times f / distance; the image holds half floats.
    float acrossLength = length(moved);
    vec2 axis = acrossLength > spacing.w
                    ? vec2(moved.x * moved.x - moved.y * moved.y, 2.0 * moved.x * moved.y) *
                          ((1.0 - spacing.w / acrossLength) / (acrossLength * acrossLength))
                    : vec2(0.0);
    return vec3(min(max(spacing.w, acrossLength), 6.0e4), axis);
}

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame())) || !insideRegion(pixel)) {
        return;
    }
    uint linear = uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x);  // the pixel's word
#if USE_INT64
    uint64_t key = depthIndex[linear];
    uint winner = uint(key & 0xFFFFFFFFul);
#else
    uint winner = imageLoad(pointIndex, pixel).r;
#endif
    if (winner == 0xFFFFFFFFu || winner < raster.firstPoint ||
        winner - raster.firstPoint >= raster.pointCount) {
        return;  // an empty pixel (cleared before) or another chunk's point
    }
#if USE_INT64
    imageStore(outDepth, pixel, vec4(uintBitsToFloat(uint(key >> 32))));
#endif
#if BLEND_COLORS
    // The winner is among the points summed: the count is at least 1.
    uvec4 sums = colorSums[linear];
    vec3 color = vec3(sums.rgb) / (float(sums.a) * SUBSCAN_COLOR_SUM_SCALE);
#else
    vec3 color = unpackColor(texelFetch(colors, int(winner - raster.firstPoint)).r);
#endif
    float spacingRatio = 1.0;
    if (surface.spacing.x > 0.5) {
        vec3 spacing = spacingOnScreen(winner - raster.firstPoint);
        spacingRatio = spacing.x;
        acrossLines[linear] = packHalf2x16(spacing.yz);
    }
    imageStore(outColor, pixel, vec4(color, spacingRatio));
    if (surface.normals.z > 0.5) {
#if BLEND_NORMALS
        // The points summed face the eye, so their sum is 0 only where none had a normal.
        vec3 sum = vec3(normalSums[3u * linear], normalSums[3u * linear + 1u],
                        normalSums[3u * linear + 2u]);
        vec3 normal = dot(sum, sum) > 0.0 ? normalize(sum) : vec3(0.0);
#else
        uint local = winner - raster.firstPoint;
        vec3 normal = viewNormal(local);
        normal = dot(normal, towardsEye(viewPositionOfPoint(local))) < 0.0 ? -normal : normal;
#endif
        imageStore(outNormal, pixel, vec4(normal, 0.0));
    }
}

#else
layout(local_size_x = SUBSCAN_POINTS_GROUP_SIZE) in;

#if BLEND_COLORS || BLEND_NORMALS
/// Adds chunk point `local` (at `viewPosition`, `depth`) to pixel `linear`'s sums where it
/// lies within the blends' depths behind the pixel's `nearest`.
void addToSums(uint local, vec3 viewPosition, uint linear, float depth, float nearest) {
#if BLEND_COLORS
    if (depth <= nearest * (1.0 + raster.colorBlend)) {
        uvec3 fixedPoint =
            uvec3(round(unpackColor(texelFetch(colors, int(local)).r) * SUBSCAN_COLOR_SUM_SCALE));
        atomicAdd(colorSums[linear].r, fixedPoint.r);
        atomicAdd(colorSums[linear].g, fixedPoint.g);
        atomicAdd(colorSums[linear].b, fixedPoint.b);
        atomicAdd(colorSums[linear].a, 1u);
    }
#endif
#if BLEND_NORMALS
    // A pixel width at the nearest's depth: the depth range the pixel's front surface spans
    // at 45 degrees.
    if (depth <= nearest + raster.normalBlend.x * projectiveDepth(nearest) / frame.depthRange.z) {
        // Weighted by the cosine towards the eye: a point stands for a piece of surface whose
        // area on screen is that cosine times its own, so the mean is over the pixel's visible
        // surface, as its supersampled truth averages it, and a rim's grazing points count
        // little.
        vec3 normal = viewNormal(local);
        vec3 weighted = normal * dot(normal, towardsEye(viewPosition));  // faces the eye
        ivec3 fixedPoint = ivec3(round(weighted * SUBSCAN_NORMAL_SUM_SCALE));
        atomicAdd(normalSums[3u * linear], fixedPoint.x);
        atomicAdd(normalSums[3u * linear + 1u], fixedPoint.y);
        atomicAdd(normalSums[3u * linear + 2u], fixedPoint.z);
    }
#endif
}
#endif

void main() {
    uint local = gl_GlobalInvocationID.x;
    if (local >= raster.pointCount) {
        return;
    }
    vec3 viewPosition = viewPositionOfPoint(local);
    vec2 window;
    ivec2 pixel;
    float depth;
    if (!projectToWindow(viewPosition, window, pixel, depth)) {
        return;
    }
    uint bits = floatBitsToUint(depth);
    uint index = raster.firstPoint + local;
    uint linear = uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x);  // the pixel's word
#if STAGE_DEPTH || STAGE_INT64
    if (surface.fill.w > 0.0) {
        // The point's 4x4 sub-cell (FillRemoval.glsl's outline); the atomic only for a cell
        // not yet marked, which in a dense cloud most points find marked.
        ivec2 cell = clamp(ivec2(floor(fract(window) * 4.0)), 0, 3);
        uint word = 1u << uint(cell.y * 4 + cell.x);
        if ((occupancy[linear] & word) == 0u) {
            atomicOr(occupancy[linear], word);
        }
    }
#endif
#if STAGE_DEPTH
    // The atomic only where a plain read says the point could win: where many points share a
    // pixel most lose, and on llvmpipe an image atomic costs about twice a read. A stale read
    // only lets a losing point try; the minimum stays exact.
    if (imageLoad(depthBits, pixel).r > bits) {
        imageAtomicMin(depthBits, pixel, bits);
    }
#elif STAGE_INDEX
    uint nearestBits = imageLoad(depthBits, pixel).r;
    if (nearestBits == bits) {
        imageAtomicMin(pointIndex, pixel, index);
    }
#if BLEND_COLORS || BLEND_NORMALS
    addToSums(local, viewPosition, linear, depth, uintBitsToFloat(nearestBits));
#endif
#elif STAGE_INT64
    atomicMin(depthIndex[linear], (uint64_t(bits) << 32) | uint64_t(index));
#elif STAGE_BLEND
    addToSums(local, viewPosition, linear, depth, uintBitsToFloat(uint(depthIndex[linear] >> 32)));
#endif
}
#endif
