#version 450
// The full-resolution end of the surface pipeline in one dispatch, for frames that keep only
// the picture: per pixel, level 0 of the push (PullPush), the mask (FillRemoval), the blended
// normal (Normals), the shading (Shade) and the sRGB encoding over the background (Present),
// from the pyramids those passes leave above level 0, with the anti-aliased outline
// (OutlineCoverage: the mask's share of each pixel). Pass by pass, the same work writes and reads back six full-screen images;
// here it writes the picture and "surfaceDepth". Each step is the function its pass runs, so
// the two differ only where that chain rounds its images to half floats. Defined by FinishSurfacePass:
//   SHADE_DIRECTIONAL_LIGHTS  0: the head light alone; 1: and the directional lights
//   FINISH_OUTPUT             FINISH_PICTURE: the picture; FINISH_RADIANCE_AND_DEPTH: linear
//                             radiance with the depth in alpha, for a temporal filter pass
//                             after it (a moving camera, whose blend needs the
//                             neighbourhood); FINISH_RESTART, FINISH_STILL: the
//                             temporal filter's blend too (render/Temporal.glsl), saving its
//                             pass (on llvmpipe a pass over the image costs ~5 ms before it
//                             does anything)
//   FINISH_SEES_OUTLINE       1: the mask comes from "mask" and "surfaceDepth" (FillRemoval.comp's
//                             STAGE_SURFACE_DEPTH), where the normals also find the outline
//                             (Normals.glsl); 0: the mask is tested here and "surfaceDepth"
//                             written
#define FINISH_PICTURE 0
#define FINISH_RADIANCE_AND_DEPTH 1
#define FINISH_RESTART 2
#define FINISH_STILL 3
#define FINISH_TEMPORAL (FINISH_OUTPUT >= FINISH_RESTART)
#define NORMALS_SEE_OUTLINE FINISH_SEES_OUTLINE
#include "render/FillRemoval.glsl"
#include "render/Normals.glsl"
#include "render/Shade.glsl"
#include "shared/region.glsl"
#if FINISH_TEMPORAL
#include "render/Temporal.glsl"
#endif

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
#if FINISH_OUTPUT == FINISH_RADIANCE_AND_DEPTH
layout(binding = SUBSCAN_IMAGE_OUT0, rgba32f) writeonly uniform image2D outRadianceAndDepth;
#else
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;
#endif
#if FINISH_SEES_OUTLINE
layout(binding = SUBSCAN_IMAGE_IN1, r8) readonly uniform image2D inMask;
#else
layout(binding = SUBSCAN_IMAGE_OUT1, r32f) writeonly uniform image2D outSurfaceDepth;
#endif

void main() {
    ivec2 pixel = dispatchTexel();
    if (!insideLevel(0u, pixel) || !insideRegion(pixel)) {
        return;
    }
    vec3 color = frame.background.rgb;
    float depth = kInfinity;
    vec4 filled = pushedValue(0u, pixel);
    float spacingRatio = spacingRatioAt(pixel);
#if FINISH_SEES_OUTLINE
    float coverage = imageLoad(inMask, pixel).r;
#else
    // Rounded as the mask image stores it pass by pass.
    float coverage = round(255.0 * surfaceCoverage(pixel, filled.x)) / 255.0;
#endif
    if (coverage > 0.0) {
        vec3 diffuse;
        vec3 specular;
        shadePixel(pixel, filled.x, blendedNormal(pixel, filled.x, spacingRatio), clamp(filled.yzw, 0.0, 1.0),
                   diffuse, specular);
        depth = filled.x;
        color = mix(frame.background.rgb, diffuse + specular, coverage);
    }
#if !FINISH_SEES_OUTLINE
    imageStore(outSurfaceDepth, pixel, vec4(depth));
#endif
#if FINISH_OUTPUT == FINISH_RADIANCE_AND_DEPTH
    imageStore(outRadianceAndDepth, pixel, vec4(color, depth));
#elif FINISH_OUTPUT == FINISH_PICTURE
    imageStore(outImage, pixel, vec4(linearToSrgb(color), 1.0));
#else
    vec4 current = frameSample(color, depth);
    vec4 result = current;
    float count = 1.0;
#if FINISH_OUTPUT == FINISH_STILL
    result = blendStill(pixel, current, count);
#endif
    storeHistory(pixel, result, depth, count);
    imageStore(outImage, pixel, vec4(linearToSrgb(result.rgb), 1.0));
#endif
}
