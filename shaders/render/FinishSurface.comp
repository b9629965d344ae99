#version 450
// The full-resolution end of the surface pipeline in one dispatch, for frames that keep only
// the picture: per pixel, level 0 of the push (PullPush), the mask (FillRemoval), the blended
// normal (Normals), the shading (Shade) and the sRGB encoding over the background (Present),
// from the pyramids those passes leave above level 0. Pass by pass, the same work writes and
// reads back six full-screen images; here it writes the picture and "surfaceDepth". Each step
// is the function its pass runs, so the two differ only where that chain rounds its images to
// half floats.
//   STAGE_HEAD_LIGHT  the head light alone (no directional lights)
//   STAGE_LIGHTS      the head light and the directional lights
//   STAGE_*_RADIANCE  the same, writing linear radiance for the temporal filter (no encoding)
#if defined(STAGE_LIGHTS) || defined(STAGE_LIGHTS_RADIANCE)
#define SHADE_DIRECTIONAL_LIGHTS 1
#else
#define SHADE_DIRECTIONAL_LIGHTS 0
#endif
#if defined(STAGE_HEAD_LIGHT_RADIANCE) || defined(STAGE_LIGHTS_RADIANCE)
#define WRITE_RADIANCE 1
#else
#define WRITE_RADIANCE 0
#endif
#include "render/FillRemoval.glsl"
#include "render/Normals.glsl"
#include "render/Shade.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
#if WRITE_RADIANCE
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outRadiance;
#else
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;
#endif
layout(binding = SUBSCAN_IMAGE_OUT1, r32f) writeonly uniform image2D outSurfaceDepth;

void main() {
    ivec2 pixel = dispatchTexel();
    if (!insideLevel(0u, pixel) || !insideRegion(pixel)) {
        return;
    }
    vec4 filled = pushedValue(0u, pixel);
    bool surfacePixel = onSurface(pixel, filled.x);
    vec3 color = frame.background.rgb;
    if (surfacePixel) {
        vec3 diffuse;
        vec3 specular;
        shadePixel(pixel, filled.x, blendedNormal(pixel, filled.x), clamp(filled.yzw, 0.0, 1.0),
                   diffuse, specular);
        color = diffuse + specular;
    }
#if WRITE_RADIANCE
    imageStore(outRadiance, pixel, vec4(color, 1.0));
#else
    imageStore(outImage, pixel, vec4(linearToSrgb(color), 1.0));
#endif
    imageStore(outSurfaceDepth, pixel, vec4(surfacePixel ? filled.x : kInfinity));
}
