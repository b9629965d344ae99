#version 450
// The anti-aliased outline on the frame's final linear colour, in place: its alpha becomes
// "mask", the share of the pixel the surface covers (FillRemoval.glsl's surfaceCoverage).
// Present and the temporal filter show the colour over the background by that share.
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, r8) readonly uniform image2D inMask;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) uniform image2D color;

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame())) || !insideRegion(pixel)) {
        return;
    }
    imageStore(color, pixel, vec4(imageLoad(color, pixel).rgb, imageLoad(inMask, pixel).r));
}
