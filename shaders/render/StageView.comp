#version 450
// Shows an intermediate buffer of the surface pipeline as a picture (the panels of the paper's
// Figure 2), in linear RGB with the background where the buffer holds nothing.
//   STAGE_DEPTH       rasterized depth, near bright
//   STAGE_PYRAMID     the min-depth pyramid on level `level`, nearest-upsampled
//   STAGE_VISIBILITY  visible points in their colour, hidden points red
//   STAGE_PULL        the pulled colour on level `level` over the background by its weight
//   STAGE_PUSH        the filled colour before fill removal
//   STAGE_FILL        the surface mask: kept fill in its colour, removed fill dark red
//   STAGE_NORMALS     view-space normals as 0.5 + 0.5 n
#include "shared/pyramid.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
layout(std430, binding = SUBSCAN_SSBO_PYRAMID) readonly buffer Pyramid {
    float minDepth[];
};
layout(std430, binding = SUBSCAN_SSBO_PULL_VALUES) readonly buffer PullValues {
    vec4 pullValue[];
};
layout(std430, binding = SUBSCAN_SSBO_PULL_WEIGHTS) readonly buffer PullWeights {
    vec2 pullWeight[];  // w, w * local spacing ratio
};
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inColor;
layout(binding = SUBSCAN_IMAGE_IN2, r8) readonly uniform image2D inFlag;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outStage;

vec3 depthShade(float depth) {
    float t = clamp((depth - frame.depthRange.x) / (frame.depthRange.y - frame.depthRange.x),
                    0.0, 1.0);
    return isinf(depth) ? frame.background.rgb : vec3(mix(0.9, 0.05, t));
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSizeOfFrame()))) {
        return;
    }
    vec3 result = frame.background.rgb;
#if STAGE_DEPTH
    result = depthShade(imageLoad(inDepth, pixel).r);
#elif STAGE_PYRAMID
    result = depthShade(minDepth[texelIndex(level, pixel >> level)]);
#elif STAGE_VISIBILITY
    if (!isinf(imageLoad(inDepth, pixel).r)) {
        result = imageLoad(inFlag, pixel).r > 0.5 ? imageLoad(inColor, pixel).rgb
                                                  : vec3(0.8, 0.02, 0.02);
    }
#elif STAGE_PULL
    uint index = texelIndex(level, pixel >> level);
    float weight = pullWeight[index].x;
    if (weight > 0.0) {
        result = mix(frame.background.rgb, pullValue[index].yzw / weight, weight);
    }
#elif STAGE_PUSH
    result = imageLoad(inColor, pixel).rgb;
#elif STAGE_FILL
    result = imageLoad(inFlag, pixel).r > 0.5 ? imageLoad(inColor, pixel).rgb
                                              : vec3(0.25, 0.02, 0.02);
#elif STAGE_NORMALS
    vec4 normal = imageLoad(inColor, pixel);
    result = normal.w > 0.0 ? 0.5 + 0.5 * normal.xyz : frame.background.rgb;
#endif
    imageStore(outStage, pixel, vec4(result, 1.0));
}
