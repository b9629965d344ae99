#version 450
// Final image: linear colour -> sRGB 8-bit.
//   STAGE_DEPTH  pixels where the depth input is +inf show the background
//   STAGE_COLOR  the colour already includes the background
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inColor;
#if STAGE_DEPTH
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
#endif
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame()))) {
        return;
    }
    vec3 color = imageLoad(inColor, pixel).rgb;
#if STAGE_DEPTH
    if (isinf(imageLoad(inDepth, pixel).r)) {
        color = frame.background.rgb;
    }
#endif
    imageStore(outImage, pixel, vec4(linearToSrgb(color), 1.0));
}
