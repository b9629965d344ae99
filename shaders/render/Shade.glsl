// The shading model of Shade.comp, for it and FinishSurface.comp (which shades level 0 itself).
#include "shared/common.glsl"

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
    for (uint i = 0u; i < shade.lightCount.x; ++i) {
        addLight(shade.lightDirection[i].xyz, shade.lightColor[i].rgb, normal, toEye, irradiance,
                 specular);
    }
    diffuse = albedo * irradiance;
}
