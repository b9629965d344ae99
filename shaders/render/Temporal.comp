#version 450
// The temporal filter as its own pass (render/Temporal.glsl): this frame's linear colour over
// the background, rendered through a sub-pixel jittered camera, blended into the previous
// result reprojected to it. The surface mode's full-resolution frames do the same inside
// FinishSurface.comp instead.
// Each mode is its own variant (STAGE_RESTART, STAGE_STILL, STAGE_MOVING): llvmpipe runs both
// sides of a branch, so one shader would make a still frame pay for the moving one's
// neighbourhood. The *_PICTURE variants also write the sRGB picture (Present's work, at full
// resolution). Defined by TemporalPass:
//   TEMPORAL_DEPTH_IN_ALPHA  1: the frame's depth is its colour image's alpha (FinishSurface's
//                            moving frames), one image load a texel instead of two (on
//                            llvmpipe the loads are most of this pass's cost); 0: "surfaceDepth",
//                            and the colour's alpha is the share of the pixel the surface
//                            covers (OutlineCoverage.comp)
#define MODE_STILL (STAGE_STILL || STAGE_STILL_PICTURE)
#define MODE_MOVING (STAGE_MOVING || STAGE_MOVING_PICTURE)
#define WRITE_PICTURE (STAGE_RESTART_PICTURE || STAGE_STILL_PICTURE || STAGE_MOVING_PICTURE)
#include "shared/common.glsl"
#include "shared/region.glsl"
#include "render/Temporal.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
#if TEMPORAL_DEPTH_IN_ALPHA
layout(binding = SUBSCAN_IMAGE_IN0, rgba32f) readonly uniform image2D inRadianceAndDepth;
#else
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inRadiance;
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
#endif
#if WRITE_PICTURE
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;
#endif

/// This frame at `texel`: its sample (colour over the background, coverage) and its depth.
vec4 frameSampleAt(ivec2 texel, out float depth) {
#if TEMPORAL_DEPTH_IN_ALPHA
    vec4 value = imageLoad(inRadianceAndDepth, texel);
    depth = value.a;
    return frameSample(value.rgb, depth);
#else
    depth = imageLoad(inDepth, texel).r;
    if (isinf(depth)) {
        return vec4(frame.background.rgb, 0.0);
    }
    vec4 color = imageLoad(inRadiance, texel);
    return frameSample(mix(frame.background.rgb, color.rgb, color.a), depth);
#endif
}

/// Adds this frame's sample at `texel` (clamped to the image) to `around`.
void addNeighbour(inout Neighbourhood around, ivec2 texel) {
    texel = clamp(texel, ivec2(0), imageSizeOfFrame() - 1);
    float depth;
    vec4 value = frameSampleAt(texel, depth);
    addSample(around, texel, value, depth);
}

void main() {
    ivec2 pixel = dispatchTexel();
    ivec2 size = imageSizeOfFrame();
    if (any(greaterThanEqual(pixel, size)) || !insideRegion(pixel)) {
        return;
    }
    float depth;
    vec4 current = frameSampleAt(pixel, depth);
    vec4 result = current;
    float count = 1.0;
#if MODE_STILL
    result = blendStill(pixel, current, count);
#elif MODE_MOVING
    Neighbourhood around = emptyNeighbourhood(pixel);
    // The 3x3 neighbourhood in row order, written out (a loop over an array of offsets cost
    // llvmpipe a third more).
    addNeighbour(around, pixel + ivec2(-1, -1));
    addNeighbour(around, pixel + ivec2(0, -1));
    addNeighbour(around, pixel + ivec2(1, -1));
    addNeighbour(around, pixel + ivec2(-1, 0));
    addSample(around, pixel, current, depth);
    addNeighbour(around, pixel + ivec2(1, 0));
    addNeighbour(around, pixel + ivec2(-1, 1));
    addNeighbour(around, pixel + ivec2(0, 1));
    addNeighbour(around, pixel + ivec2(1, 1));
    result = blendMoving(pixel, current, depth, around, count);
#endif
    storeHistory(pixel, result, depth, count);
#if WRITE_PICTURE
    imageStore(outImage, pixel, vec4(linearToSrgb(result.rgb), 1.0));
#endif
}
