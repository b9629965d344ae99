#version 450
// Compute rasterization of 1-pixel points (Schuetz et al. 2021): per pixel keep the nearest
// point, ties broken by the smaller point index, so every path gives the same winner.
//   STAGE_DEPTH    one thread per point: 32-bit atomicMin of the depth bits
//   STAGE_INDEX    one thread per point: among points at the winning depth, atomicMin of index
//   STAGE_INT64    one thread per point: one 64-bit atomicMin of depthBits << 32 | index
//   STAGE_RESOLVE  one thread per pixel: the winner's depth and linear colour into images
// Positive IEEE floats order like their bit patterns, so depth bits compare as uints.
#if STAGE_INT64 || (STAGE_RESOLVE && USE_INT64)
#extension GL_ARB_gpu_shader_int64 : require
#extension GL_NV_shader_atomic_int64 : require
#endif
#include "shared/common.glsl"

layout(std140, binding = SUBSCAN_UBO_PASS) uniform RasterBlock {
    RasterParams raster;
};
layout(std430, binding = SUBSCAN_SSBO_POSITIONS) readonly buffer Positions {
    float positions[];
};
layout(std430, binding = SUBSCAN_SSBO_COLORS) readonly buffer Colors {
    uint colors[];
};
layout(std430, binding = SUBSCAN_SSBO_DEPTH_BITS) buffer DepthBits {
    uint depthBits[];
};
layout(std430, binding = SUBSCAN_SSBO_POINT_INDEX) buffer PointIndex {
    uint pointIndex[];
};
#if STAGE_INT64 || (STAGE_RESOLVE && USE_INT64)
layout(std430, binding = SUBSCAN_SSBO_DEPTH_INDEX) buffer DepthIndex {
    uint64_t depthIndex[];
};
#endif

#if STAGE_RESOLVE
layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_OUT0, r32f) writeonly uniform image2D outDepth;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outColor;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSizeOfFrame()))) {
        return;
    }
    uint linear = uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x);
#if USE_INT64
    uint64_t key = depthIndex[linear];
    uint winner = uint(key & 0xFFFFFFFFul);
    float depth = uintBitsToFloat(uint(key >> 32));
#else
    uint winner = pointIndex[linear];
    float depth = uintBitsToFloat(depthBits[linear]);
#endif
    if (winner == 0xFFFFFFFFu) {
        // Empty pixel: written once, by the dispatch of the first chunk.
        if (raster.firstPoint == 0u) {
            imageStore(outDepth, pixel, vec4(kInfinity));
            imageStore(outColor, pixel, vec4(0.0));
        }
        return;
    }
    if (winner < raster.firstPoint || winner - raster.firstPoint >= raster.pointCount) {
        return;  // another chunk's point
    }
    imageStore(outDepth, pixel, vec4(depth));
    imageStore(outColor, pixel, vec4(unpackColor(colors[winner - raster.firstPoint]), 1.0));
}

#else
layout(local_size_x = SUBSCAN_POINTS_GROUP_SIZE) in;

void main() {
    uint local = gl_GlobalInvocationID.x;
    if (local >= raster.pointCount) {
        return;
    }
    vec3 position = vec3(positions[3u * local], positions[3u * local + 1u],
                         positions[3u * local + 2u]);
    vec3 viewPosition = (frame.viewFromCloud * vec4(position, 1.0)).xyz;
    ivec2 pixel;
    float depth;
    if (!projectToPixel(viewPosition, pixel, depth)) {
        return;
    }
    uint linear = uint(pixel.y) * uint(frame.viewport.x) + uint(pixel.x);
    uint bits = floatBitsToUint(depth);
    uint index = raster.firstPoint + local;
#if STAGE_DEPTH
    atomicMin(depthBits[linear], bits);
#elif STAGE_INDEX
    if (depthBits[linear] == bits) {
        atomicMin(pointIndex[linear], index);
    }
#elif STAGE_INT64
    atomicMin(depthIndex[linear], (uint64_t(bits) << 32) | uint64_t(index));
#endif
}
#endif
