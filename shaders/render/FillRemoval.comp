#version 450
// Fill removal: pull-push also fills the background around the object. A pixel belongs to the
// surface when it holds a visible point (unless it lies beyond a dense cloud's outline:
// FillRemoval.glsl's surfaceCoverage), or when points surround it: in (by default) all 8
// directions, some level up to the expected-gap level L(x) (at least 1) finds pull weight in
// the neighbouring texel, or from level 1 on any point, hidden ones too (FillRemoval.glsl's
// weighted). This replaces the paper's threshold on the pull weight at L(x), which spreads the
// mask past the silhouette by about a texel of L(x) (the coarse weight is interpolated across
// the edge): measured on the Stanford bunny, leakage fell from 4.6 % to 2 % at equal coverage
// (bench/README.md).
//   STAGE_REACH  level `level` (coarsest first) of the "fillReach" pyramid: per direction k,
//                in 4 bits, the finest level l' >= level whose texel (t >> (l' - level)) + d_k
//                is weighted (FillRemoval.glsl; 15: none). A texel takes its own
//                neighbour's level or else its parent's answer, so the mask stage reads 9
//                values per pixel instead of walking up to 8 x (L(x) + 1) texels: on
//                close-ups, where L(x) is large, that walk dominated the frame. On level 1
//                also "fillSparse" (FillRemoval.glsl's sparseEnclosure).
//   STAGE_MASK   writes "mask" (the share of the pixel the surface covers: 0 off it, 1 on
//                it but at the sub-pixel outline) and "surfaceDepth" (the filled depth on the
//                surface, +inf elsewhere), unless FinishSurface.comp tests level 0 itself.
//   STAGE_SURFACE_DEPTH  the same from the push's level 0 (which FinishSurface.comp computes
//                for itself): for a FinishSurface whose normals look for the outline around
//                each pixel, which one dispatch cannot know of its neighbours.
#include "render/FillRemoval.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
// Written as a storage buffer, read as a buffer texture (see Buffer::bindTexels).
layout(std430, binding = SUBSCAN_SSBO_FILL_REACH) writeonly buffer FillReach {
    uint fillReach[];
};
#if STAGE_REACH
layout(std430, binding = SUBSCAN_SSBO_FILL_SPARSE) writeonly buffer FillSparse {
    uint fillSparse[];
};
#endif
#if STAGE_MASK
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inFilledDepth;
#endif
#if STAGE_MASK || STAGE_SURFACE_DEPTH
layout(binding = SUBSCAN_IMAGE_OUT0, r8) writeonly uniform image2D outMask;
layout(binding = SUBSCAN_IMAGE_OUT1, r32f) writeonly uniform image2D outSurfaceDepth;
#endif

void main() {
#if STAGE_REACH
    ivec2 texel = dispatchTexel();
    if (insideLevel(level, texel) && insideRegion(texel)) {
        uint reach = reachOf(level, texel);
        fillReach[texelIndex(level, texel)] = reach;
        if (level == 1u) {
            fillSparse[fillSparseIndex(texel)] = sparseEnclosure(texel, reach);
        }
    }
#else
    ivec2 pixel = dispatchTexel();
    if (!insideLevel(0u, pixel) || !insideRegion(pixel)) {
        return;
    }
#if STAGE_MASK
    float depth = imageLoad(inFilledDepth, pixel).r;
#else
    float depth = pushedValue(0u, pixel).x;
#endif
    float coverage = surfaceCoverage(pixel, depth);
    imageStore(outMask, pixel, vec4(coverage));
    imageStore(outSurfaceDepth, pixel, vec4(coverage > 0.0 ? depth : kInfinity));
#endif
}
