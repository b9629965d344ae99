#version 450
// Fill removal: pull-push also fills the background around the object. A pixel belongs to the
// surface when it holds a visible point, or when visible points surround it: in (by default)
// all 8 directions, some level up to the expected-gap level L(x) (at least 1) finds pull weight
// in the neighbouring texel. This replaces the paper's threshold on the pull weight at L(x),
// which spreads the mask past the silhouette by about a texel of L(x) (the coarse weight is
// interpolated across the edge): measured on the Stanford bunny, leakage fell from 4.6 % to 2 %
// at equal coverage (bench/README.md). Writes "mask" (1 = surface) and "surfaceDepth" (the
// filled depth there, +inf elsewhere).
#include "shared/pyramid.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_SURFACE) uniform SurfaceBlock {
    SurfaceParams surface;
};
layout(std430, binding = SUBSCAN_SSBO_PULL_WEIGHTS) readonly buffer PullWeights {
    float pullWeight[];
};
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inFilledDepth;
layout(binding = SUBSCAN_IMAGE_OUT0, r8) writeonly uniform image2D outMask;
layout(binding = SUBSCAN_IMAGE_OUT1, r32f) writeonly uniform image2D outSurfaceDepth;

const ivec2 kDirections[8] = ivec2[](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1),
                                     ivec2(-1, 0), ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

void main() {
    ivec2 pixel = dispatchTexel();
    if (!insideLevel(0u, pixel)) {
        return;
    }
    float depth = imageLoad(inFilledDepth, pixel).r;
    bool surfacePixel = false;
    if (depth > 0.0 && !isinf(depth) && !isnan(depth)) {
        if (pullWeight[texelIndex(0u, pixel)] > 0.0) {
            surfacePixel = true;
        } else {
            // Level 1 at least: its texels bridge one-pixel gaps between dense points.
            uint levels = uint(ceil(clamp(levelForRadius(surface.fill.x, depth), 1.0,
                                          float(levelCount() - 1u))));
            int enclosed = 0;
            // Stops as soon as the remaining directions can no longer reach the count: most
            // background pixels fail on their first empty direction.
            for (int k = 0; k < 8 && float(enclosed + 8 - k) >= surface.fill.y; ++k) {
                bool found = false;
                for (uint level = 0u; level <= levels && !found; ++level) {
                    ivec2 texel = (pixel >> level) + kDirections[k];
                    found = insideLevel(level, texel) && pullWeight[texelIndex(level, texel)] > 0.0;
                }
                enclosed += found ? 1 : 0;
            }
            surfacePixel = float(enclosed) >= surface.fill.y;
        }
    }
    imageStore(outMask, pixel, vec4(surfacePixel ? 1.0 : 0.0));
    imageStore(outSurfaceDepth, pixel, vec4(surfacePixel ? depth : kInfinity));
}
