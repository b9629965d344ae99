// The shading model of Shade.comp, for it and FinishSurface.comp (which shades level 0 itself).
// An includer may define SHADE_DIRECTIONAL_LIGHTS 0 for frames with the head light alone: on
// llvmpipe the loop over the directional lights costs even when it runs zero times.
#include "shared/common.glsl"

#ifndef SHADE_DIRECTIONAL_LIGHTS
#define SHADE_DIRECTIONAL_LIGHTS 1
#endif

layout(std140, binding = SUBSCAN_UBO_PASS) uniform ShadeBlock {
    ShadeParams shade;
};

void addLight(vec3 direction, vec3 radiance, vec3 normal, vec3 toEye, inout vec3 diffuse,
              inout vec3 specular) {
    float cosine = dot(normal, direction);
    if (cosine <= 0.0) {
        return;
    }
    vec3 halfway = normalize(direction + toEye);
    diffuse += radiance * cosine;
    specular += radiance * cosine * shade.specular.x *
                pow(max(dot(normal, halfway), 0.0), shade.specular.y);
}

/// The radiance leaving surface pixel `pixel` at `depth` towards the eye, by diffuse
/// reflection of `albedo` (0..1) and by specular reflection.
void shadePixel(ivec2 pixel, float depth, vec3 normal, vec3 albedo, out vec3 diffuse,
                out vec3 specular) {
    vec3 position = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toEye = normalize(-position);
    vec3 irradiance = shade.ambient.rgb;
    specular = vec3(0.0);
    addLight(toEye, shade.headLight.rgb, normal, toEye, irradiance, specular);
#if SHADE_DIRECTIONAL_LIGHTS
    for (uint i = 0u; i < shade.lightCount.x; ++i) {
        addLight(shade.lightDirection[i].xyz, shade.lightColor[i].rgb, normal, toEye, irradiance,
                 specular);
    }
#endif
    diffuse = albedo * irradiance;
}
