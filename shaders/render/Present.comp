#version 450
// Final image: linear colour -> sRGB 8-bit, scaled up to the output when the pipeline ran at
// 1/divisor of its resolution (bilinear, the background standing in for empty texels so the
// silhouette blends into it instead of taking a colour from outside the surface).
//   STAGE_DEPTH     pixels where the depth input is +inf show the background
//   STAGE_COLOR     the colour already includes the background
//   STAGE_COVERAGE  the colour's alpha is the share of the pixel the surface covers
//                   (OutlineCoverage.comp), the background shows through the rest
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_DIVISOR) uniform int divisor;
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inColor;
#if STAGE_DEPTH
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
#endif
layout(binding = SUBSCAN_IMAGE_OUT0, rgba8) writeonly uniform image2D outImage;

vec3 colorAt(ivec2 texel) {
#if STAGE_DEPTH
    if (isinf(imageLoad(inDepth, texel).r)) {
        return frame.background.rgb;
    }
#endif
#if STAGE_COVERAGE
    vec4 color = imageLoad(inColor, texel);
    return mix(frame.background.rgb, color.rgb, color.a);
#else
    return imageLoad(inColor, texel).rgb;
#endif
}

void main() {
    ivec2 pixel = dispatchTexel();
    ivec2 outputSize = imageSize(outImage);
    if (any(greaterThanEqual(pixel, outputSize)) || !insideRegion(pixel)) {
        return;
    }
    vec3 color;
    if (divisor == 1) {
        color = colorAt(pixel);
    } else {
        // ReducedResolution.h: the reduced image is centred on the output.
        ivec2 inputSize = imageSize(inColor);
        vec2 position = 0.5 * vec2(inputSize) +
                        (vec2(pixel) + 0.5 - 0.5 * vec2(outputSize)) / float(divisor) - 0.5;
        ivec2 first = ivec2(floor(position));
        vec2 t = position - vec2(first);
        ivec2 last = inputSize - 1;
        ivec2 low = clamp(first, ivec2(0), last);
        ivec2 high = clamp(first + 1, ivec2(0), last);
        color = mix(mix(colorAt(low), colorAt(ivec2(high.x, low.y)), t.x),
                    mix(colorAt(ivec2(low.x, high.y)), colorAt(high), t.x), t.y);
    }
    imageStore(outImage, pixel, vec4(linearToSrgb(color), 1.0));
}
