#version 450
// Screen-space subsurface scattering with a sum of Gaussians (DESIGN.md §6.1): the diffuse
// light is blurred by each Gaussian of the material's profile, horizontally then vertically,
// and the results are summed with per-channel weights.
//   STAGE_PREPARE          the light to blur ("sssSource": diffuse radiance, irradiance or
//                          sqrt(albedo) x irradiance, by the albedo placement) and the sum
//                          ("sssSum") started with the unblurred term's weight
//   STAGE_BLUR             one 1-D blur of "source" into "out"
//   STAGE_BLUR_ACCUMULATE  one 1-D blur of "source" into "out", and sum += weight * out
//   STAGE_COMBINE          the albedo placed after the blur, plus specular
// Each tap is weighted by the 3-D distance between its back-projected position and the
// centre's, not by its pixel offset: the blur follows the surface (foreshortening is exact) and
// ignores whatever lies at another depth, so nothing bleeds across silhouettes. Taps outside the
// surface are skipped and the weights renormalised, so a uniformly lit surface stays uniform.
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_PASS) uniform ScatterBlock {
    ScatterParams scatter;
};
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;

#if STAGE_PREPARE
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inDiffuse;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inAlbedo;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outSource;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba32f) writeonly uniform image2D outSum;
#elif STAGE_BLUR || STAGE_BLUR_ACCUMULATE
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inSource;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outBlurred;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba32f) uniform image2D sum;
#elif STAGE_COMBINE
layout(binding = SUBSCAN_IMAGE_IN1, rgba32f) readonly uniform image2D inSum;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inAlbedo;
layout(binding = SUBSCAN_IMAGE_IN3, rgba16f) readonly uniform image2D inSpecular;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outRadiance;
#endif

const uint kAlbedoBefore = 0u;
const uint kAlbedoAfter = 1u;

/// The factor the albedo contributes on one side of the blur.
vec3 albedoFactor(vec3 albedo, uint side) {
    if (scatter.albedo.x == side) {
        return albedo;
    }
    return scatter.albedo.x == 2u ? sqrt(albedo) : vec3(1.0);
}

void main() {
    ivec2 pixel = dispatchTexel();
    ivec2 size = imageSizeOfFrame();
    if (any(greaterThanEqual(pixel, size)) || !insideRegion(pixel)) {
        return;
    }
    float depth = imageLoad(inSurfaceDepth, pixel).r;
    bool surface = !isinf(depth);
#if !STAGE_COMBINE
    // The chain never reads its images outside the surface (taps there are skipped), so
    // background pixels need no writes: most of a frame costs one load.
    if (!surface) {
        return;
    }
#endif
#if STAGE_PREPARE
    // "diffuse" is albedo x irradiance; the irradiance is recovered where the albedo is not
    // zero (where it is, the diffuse light is zero whatever the irradiance).
    vec3 albedo = imageLoad(inAlbedo, pixel).rgb;
    vec3 diffuse = imageLoad(inDiffuse, pixel).rgb;
    vec3 source =
        mix(vec3(0.0), diffuse * albedoFactor(albedo, kAlbedoBefore) / max(albedo, vec3(1e-6)),
            greaterThan(albedo, vec3(0.0)));
    imageStore(outSource, pixel, vec4(source, 1.0));
    imageStore(outSum, pixel, vec4(scatter.weight.rgb * source, 1.0));
#elif STAGE_BLUR || STAGE_BLUR_ACCUMULATE
    float sigma = scatter.blur.x;
    float sigmaPixels = sigma * frame.depthRange.z / projectiveDepth(depth);
    float reach = 3.0 * sigmaPixels;
    int maxTaps = int(scatter.blur.y);
    // Every pixel while the kernel fits the tap budget; a larger stride beyond it.
    int taps = int(min(ceil(reach), float(maxTaps)));
    float stride = taps > 0 && ceil(reach) > float(maxTaps) ? reach / float(taps) : 1.0;
    ivec2 axis = scatter.blur.z > 0.5 ? ivec2(0, 1) : ivec2(1, 0);
    vec3 centre = viewPositionAt(vec2(pixel) + 0.5, depth);
    float inverseTwoVariance = 1.0 / (2.0 * sigma * sigma);
    vec3 total = imageLoad(inSource, pixel).rgb;
    float totalWeight = 1.0;
    for (int k = -taps; k <= taps; ++k) {
        ivec2 tap = pixel + axis * int(round(float(k) * stride));
        if (k == 0 || any(lessThan(tap, ivec2(0))) || any(greaterThanEqual(tap, size))) {
            continue;
        }
        float tapDepth = imageLoad(inSurfaceDepth, tap).r;
        if (isinf(tapDepth)) {
            continue;
        }
        vec3 offset = viewPositionAt(vec2(tap) + 0.5, tapDepth) - centre;
        float weight = exp(-dot(offset, offset) * inverseTwoVariance);
        total += weight * imageLoad(inSource, tap).rgb;
        totalWeight += weight;
    }
    vec3 blurred = total / totalWeight;
    imageStore(outBlurred, pixel, vec4(blurred, 1.0));
#if STAGE_BLUR_ACCUMULATE
    vec4 accumulated = imageLoad(sum, pixel);
    imageStore(sum, pixel, vec4(accumulated.rgb + scatter.weight.rgb * blurred, 1.0));
#endif
#elif STAGE_COMBINE
    vec4 radiance = vec4(0.0);
    if (surface) {
        vec3 albedo = imageLoad(inAlbedo, pixel).rgb;
        radiance = vec4(albedoFactor(albedo, kAlbedoAfter) * imageLoad(inSum, pixel).rgb +
                            imageLoad(inSpecular, pixel).rgb,
                        1.0);
    }
    imageStore(outRadiance, pixel, radiance);
#endif
}
