#version 450
// Fill removal (paper §4, "Rendering"): pull-push also fills the background around the object.
// A pixel belongs to the surface only if the pull weight around it, read on the level of the
// expected gap between points there, reaches a threshold. Writes "mask" (1 = surface) and
// "surfaceDepth" (the filled depth on the surface, +inf elsewhere).
#include "shared/pyramid.glsl"

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

float weightOnLevel(uint level, vec2 window) {
    ivec2 texels[4];
    float weights[4];
    bilinearTexels(level, window, texels, weights);
    float sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        sum += weights[i] * pullWeight[texelIndex(level, texels[i])];
    }
    return sum;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (!insideLevel(0u, pixel)) {
        return;
    }
    float depth = imageLoad(inFilledDepth, pixel).r;
    bool surfacePixel = false;
    if (depth > 0.0 && !isinf(depth) && !isnan(depth)) {
        float level = clamp(levelForRadius(surface.fill.x, depth), 0.0, float(levelCount() - 1u));
        uint lower = uint(level);
        uint upper = min(lower + 1u, levelCount() - 1u);
        vec2 window = vec2(pixel) + 0.5;
        float weight = mix(weightOnLevel(lower, window), weightOnLevel(upper, window),
                           level - float(lower));
        surfacePixel = weight >= surface.fill.y;
    }
    imageStore(outMask, pixel, vec4(surfacePixel ? 1.0 : 0.0));
    imageStore(outSurfaceDepth, pixel, vec4(surfacePixel ? depth : kInfinity));
}
