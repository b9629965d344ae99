#version 450
// The temporal filter as its own pass (render/Temporal.glsl): this frame's linear colour over
// the background, rendered through a sub-pixel jittered camera, blended into the previous
// result reprojected to it. The surface mode's full-resolution frames do the same inside
// FinishSurface.comp instead.
// Each mode is its own variant (STAGE_RESTART, STAGE_STILL, STAGE_MOVING): llvmpipe runs both
// sides of a branch, so one shader would make a still frame pay for the moving one's
// neighbourhood. The *_PICTURE variants also write the sRGB picture (Present's work, at full
// resolution).
#define MODE_STILL (STAGE_STILL || STAGE_STILL_PICTURE)
#define MODE_MOVING (STAGE_MOVING || STAGE_MOVING_PICTURE)
#define WRITE_PICTURE (STAGE_RESTART_PICTURE || STAGE_STILL_PICTURE || STAGE_MOVING_PICTURE)
#include "shared/common.glsl"
#include "shared/region.glsl"
#include "render/Temporal.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inRadiance;
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
#if WRITE_PICTURE
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;
#endif

/// This frame at `texel` of depth `depth`, reading the radiance only on the surface.
vec4 frameSampleAt(ivec2 texel, float depth) {
    return isinf(depth) ? vec4(frame.background.rgb, 0.0)
                        : frameSample(imageLoad(inRadiance, texel).rgb, depth);
}

void main() {
    ivec2 pixel = dispatchTexel();
    ivec2 size = imageSizeOfFrame();
    if (any(greaterThanEqual(pixel, size)) || !insideRegion(pixel)) {
        return;
    }
    float depth = imageLoad(inDepth, pixel).r;
    vec4 current = frameSampleAt(pixel, depth);
    vec4 result = current;
    float count = 1.0;
#if MODE_STILL
    result = blendStill(pixel, current, count);
#elif MODE_MOVING
    Neighbourhood around = emptyNeighbourhood(pixel);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 texel = clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1);
            bool centre = dx == 0 && dy == 0;
            float d = centre ? depth : imageLoad(inDepth, texel).r;
            addSample(around, texel, centre ? current : frameSampleAt(texel, d), d);
        }
    }
    result = blendMoving(pixel, current, depth, around, count);
#endif
    storeHistory(pixel, result, depth, count);
#if WRITE_PICTURE
    imageStore(outImage, pixel, vec4(linearToSrgb(result.rgb), 1.0));
#endif
}
