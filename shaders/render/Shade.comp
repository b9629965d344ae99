#version 450
// Deferred shading of the reconstructed surface: Lambert + Blinn-Phong under a light at the eye
// and optional directional lights, plus ambient. Writes "radiance"; STAGE_SPLIT also writes its
// parts for the scattering passes: "diffuse" (radiance leaving by diffuse reflection),
// "specular" and "albedo". Background pixels are zero in all of them.
#include "render/Shade.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inNormals;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inFilledColor;
#if STAGE_SPLIT
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outDiffuse;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outSpecular;
layout(binding = SUBSCAN_IMAGE_OUT2, rgba16f) writeonly uniform image2D outAlbedo;
#endif
layout(binding = SUBSCAN_IMAGE_OUT3, rgba16f) writeonly uniform image2D outRadiance;

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame())) || !insideRegion(pixel)) {
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
    vec3 normal = imageLoad(inNormals, pixel).xyz;
    vec3 albedo = clamp(imageLoad(inFilledColor, pixel).rgb, 0.0, 1.0);
    vec3 diffuse;
    vec3 specular;
    shadePixel(pixel, depth, normal, albedo, diffuse, specular);
#if STAGE_SPLIT
    imageStore(outDiffuse, pixel, vec4(diffuse, 1.0));
    imageStore(outSpecular, pixel, vec4(specular, 1.0));
    imageStore(outAlbedo, pixel, vec4(albedo, 1.0));
#endif
    imageStore(outRadiance, pixel, vec4(diffuse + specular, 1.0));
}
