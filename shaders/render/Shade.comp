#version 450
// Deferred shading of the reconstructed surface: Lambert + Blinn-Phong under a light at the eye
// and optional directional lights, plus ambient. Writes "radiance"; STAGE_SPLIT also writes its
// parts for the scattering passes: "diffuse" (radiance leaving by diffuse reflection),
// "specular" and "albedo". Background pixels are zero in all of them.
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_PASS) uniform ShadeBlock {
    ShadeParams shade;
};
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inNormals;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inFilledColor;
#if STAGE_SPLIT
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outDiffuse;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outSpecular;
layout(binding = SUBSCAN_IMAGE_OUT2, rgba16f) writeonly uniform image2D outAlbedo;
#endif
layout(binding = SUBSCAN_IMAGE_OUT3, rgba16f) writeonly uniform image2D outRadiance;

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

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame()))) {
        return;
    }
    float depth = imageLoad(inSurfaceDepth, pixel).r;
    if (isinf(depth)) {
#if STAGE_SPLIT
        imageStore(outDiffuse, pixel, vec4(0.0));
        imageStore(outSpecular, pixel, vec4(0.0));
        imageStore(outAlbedo, pixel, vec4(0.0));
#endif
        imageStore(outRadiance, pixel, vec4(0.0));
        return;
    }
    vec3 position = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toEye = normalize(-position);
    vec3 normal = imageLoad(inNormals, pixel).xyz;
    vec3 albedo = clamp(imageLoad(inFilledColor, pixel).rgb, 0.0, 1.0);

    vec3 irradiance = shade.ambient.rgb;
    vec3 specular = vec3(0.0);
    addLight(toEye, shade.headLight.rgb, normal, toEye, irradiance, specular);
    for (uint i = 0u; i < shade.lightCount.x; ++i) {
        addLight(shade.lightDirection[i].xyz, shade.lightColor[i].rgb, normal, toEye, irradiance,
                 specular);
    }
    vec3 diffuse = albedo * irradiance;
#if STAGE_SPLIT
    imageStore(outDiffuse, pixel, vec4(diffuse, 1.0));
    imageStore(outSpecular, pixel, vec4(specular, 1.0));
    imageStore(outAlbedo, pixel, vec4(albedo, 1.0));
#endif
    imageStore(outRadiance, pixel, vec4(diffuse + specular, 1.0));
}
