#version 450
// The viewer's cross-fade from the picture it showed to a new one (a streamed view's new nodes):
// the two sRGB-encoded pictures mixed in linear light, so that a fade passes through the
// radiances between them rather than through darker ones.
#include "shared/common.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_FADE) uniform float newWeight;
layout(binding = SUBSCAN_IMAGE_IN0, rgba8) readonly uniform image2D oldImage;
layout(binding = SUBSCAN_IMAGE_IN1, rgba8) readonly uniform image2D newImage;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(outImage)))) {
        return;
    }
    vec3 before = srgbToLinear(imageLoad(oldImage, pixel).rgb);
    vec3 after = srgbToLinear(imageLoad(newImage, pixel).rgb);
    imageStore(outImage, pixel, vec4(linearToSrgb(mix(before, after, newWeight)), 1.0));
}
