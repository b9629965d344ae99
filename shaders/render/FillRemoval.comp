#version 450
// Fill removal: pull-push also fills the background around the object. A pixel belongs to the
// surface when it holds a visible point, or when visible points surround it: in (by default)
// all 8 directions, some level up to the expected-gap level L(x) (at least 1) finds pull weight
// in the neighbouring texel. This replaces the paper's threshold on the pull weight at L(x),
// which spreads the mask past the silhouette by about a texel of L(x) (the coarse weight is
// interpolated across the edge): measured on the Stanford bunny, leakage fell from 4.6 % to 2 %
// at equal coverage (bench/README.md).
//   STAGE_REACH  level `level` (coarsest first) of the "fillReach" pyramid: per direction k,
//                in 4 bits, the finest level l' >= level whose texel (t >> (l' - level)) + d_k
//                has pull weight (15: none). A texel takes its own neighbour's level or else its
//                parent's answer, so the mask stage reads 9 values per pixel instead of
//                walking up to 8 x (L(x) + 1) texels: on close-ups, where L(x) is large, that
//                walk dominated the frame.
//   STAGE_MASK   writes "mask" (1 = surface) and "surfaceDepth" (the filled depth there, +inf
//                elsewhere).
#include "shared/pyramid.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
layout(std140, binding = SUBSCAN_UBO_SURFACE) uniform SurfaceBlock {
    SurfaceParams surface;
};
layout(binding = SUBSCAN_TEXELS_PULL_WEIGHTS) uniform samplerBuffer pullWeightTexels;
// Written as a storage buffer, read as a buffer texture (see Buffer::bindTexels).
layout(std430, binding = SUBSCAN_SSBO_FILL_REACH) writeonly buffer FillReach {
    uint fillReach[];
};
layout(binding = SUBSCAN_TEXELS_FILL_REACH) uniform usamplerBuffer fillReachTexels;

float pullWeightAt(uint index) { return texelFetch(pullWeightTexels, int(index)).r; }
#if STAGE_MASK
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inFilledDepth;
layout(binding = SUBSCAN_IMAGE_OUT0, r8) writeonly uniform image2D outMask;
layout(binding = SUBSCAN_IMAGE_OUT1, r32f) writeonly uniform image2D outSurfaceDepth;
#endif

const ivec2 kDirections[8] = ivec2[](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1),
                                     ivec2(-1, 0), ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));
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

void main() {
#if STAGE_REACH
    ivec2 texel = dispatchTexel();
    if (insideLevel(level, texel)) {
        fillReach[texelIndex(level, texel)] = reachOf(level, texel);
    }
#else
    ivec2 pixel = dispatchTexel();
    if (!insideLevel(0u, pixel)) {
        return;
    }
    float depth = imageLoad(inFilledDepth, pixel).r;
    bool surfacePixel = false;
    if (depth > 0.0 && !isinf(depth) && !isnan(depth)) {
        if (pullWeightAt(texelIndex(0u, pixel)) > 0.0) {
            surfacePixel = true;
        } else {
            // Level 1 at least: its texels bridge one-pixel gaps between dense points.
            uint levels = uint(ceil(clamp(levelForRadius(surface.fill.x, depth), 1.0,
                                          float(levelCount() - 1u))));
            // kNoReach never counts: it could only mean the top level, whose one texel has
            // no neighbours.
            levels = min(levels, kNoReach - 1u);
            uint reach = reachOf(0u, pixel);
            int enclosed = 0;
            for (int k = 0; k < 8; ++k) {
                enclosed += ((reach >> (4 * k)) & 0xFu) <= levels ? 1 : 0;
            }
            surfacePixel = float(enclosed) >= surface.fill.y;
        }
    }
    imageStore(outMask, pixel, vec4(surfacePixel ? 1.0 : 0.0));
    imageStore(outSurfaceDepth, pixel, vec4(surfacePixel ? depth : kInfinity));
#endif
}
