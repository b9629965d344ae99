#version 450
// A light's reconstruction packed into its light map (LightMapPass): per texel the depth along
// the light and the normal in the light's view space, zero where the light meets nothing.
#include "shared/common.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inNormals;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba32f) writeonly uniform image2D outLightMap;

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSizeOfFrame()))) {
        return;
    }
    float depth = imageLoad(inSurfaceDepth, texel).r;
    vec3 normal = isinf(depth) ? vec3(0.0) : imageLoad(inNormals, texel).xyz;
    imageStore(outLightMap, texel, vec4(depth, normal));
}
