#version 450
// Final image: linear colour -> sRGB 8-bit; pixels with nothing in them get the background.
#include "shared/common.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inColor;
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSizeOfFrame()))) {
        return;
    }
    bool covered = imageLoad(inDepth, pixel).r < kInfinity;
    vec3 color = covered ? imageLoad(inColor, pixel).rgb : frame.background.rgb;
    imageStore(outImage, pixel, vec4(linearToSrgb(color), 1.0));
}
