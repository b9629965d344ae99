#version 450
// The temporal filter (DESIGN.md §5 step 10): this frame, rendered through a sub-pixel jittered
// camera, blended into the previous result reprojected to it. The result keeps the colour over
// the background and the share of the pixel the surface covers (alpha), so silhouettes come out
// anti-aliased; its state keeps this frame's depth (the next frame's disocclusion test) and how
// many frames the pixel's history holds.
//   restart  the frame alone
//   still    the same camera as before: an even mean of up to blend.z frames, no clipping, so
//            the picture converges to the mean over the jitter pattern (a supersampled picture)
//   moving   the history fetched where the pixel's surface was in the previous frame; taps that
//            saw another surface there are dropped (disocclusion), and what is left is clipped
//            to the new frame's neighbourhood (variance clipping in YCoCg) before the blend
// Each of the three is its own variant (STAGE_RESTART, STAGE_STILL, STAGE_MOVING): llvmpipe
// runs both sides of a branch, so one shader would make a still frame pay for the moving one's
// neighbourhood. The *_PICTURE variants also write the sRGB picture (Present's work, at full
// resolution).
#define MODE_STILL (STAGE_STILL || STAGE_STILL_PICTURE)
#define MODE_MOVING (STAGE_MOVING || STAGE_MOVING_PICTURE)
#define WRITE_PICTURE (STAGE_RESTART_PICTURE || STAGE_STILL_PICTURE || STAGE_MOVING_PICTURE)
#include "shared/common.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_PASS) uniform TemporalBlock {
    TemporalParams temporal;
};
layout(binding = SUBSCAN_IMAGE_IN0, rgba16f) readonly uniform image2D inRadiance;
layout(binding = SUBSCAN_IMAGE_IN1, r32f) readonly uniform image2D inDepth;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inHistory;
layout(binding = SUBSCAN_IMAGE_IN3, rg32f) readonly uniform image2D inHistoryState;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D outHistory;
layout(binding = SUBSCAN_IMAGE_OUT1, rg32f) writeonly uniform image2D outHistoryState;
#if WRITE_PICTURE
layout(binding = SUBSCAN_IMAGE_OUT2, rgba8) writeonly uniform image2D outImage;
#endif

vec3 toYCoCg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b,
                -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 fromYCoCg(vec3 c) { return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z); }

/// This frame at a texel of depth `depth`: colour over the background and coverage (1 on the
/// surface).
vec4 frameSample(ivec2 texel, float depth) {
    if (isinf(depth)) {
        return vec4(frame.background.rgb, 0.0);
    }
    return vec4(imageLoad(inRadiance, texel).rgb, 1.0);
}

/// Moves `history` towards `centre` until it lies inside the box centre ± extent.
vec4 clipToBox(vec4 history, vec4 centre, vec4 extent) {
    vec4 offset = history - centre;
    vec4 units = abs(offset) / max(extent, vec4(1e-6));
    float largest = max(max(units.x, units.y), max(units.z, units.w));
    return largest > 1.0 ? centre + offset / largest : history;
}

void main() {
    ivec2 pixel = dispatchTexel();
    ivec2 size = imageSizeOfFrame();
    if (any(greaterThanEqual(pixel, size)) || !insideRegion(pixel)) {
        return;
    }
    float depth = imageLoad(inDepth, pixel).r;
    vec4 current = frameSample(pixel, depth);
    vec4 result = current;
    float count = 1.0;

#if MODE_STILL
    {
        // Nothing moved: the pixel's own history, an even mean over the jitter pattern. A
        // history built while moving (resampled, clipped) counts as one frame, so that what
        // the motion left fades as 1/n once the camera stops.
        vec4 history = imageLoad(inHistory, pixel);
        float frames = temporal.flags.x == 1u ? 1.0 : imageLoad(inHistoryState, pixel).g;
        count = min(frames + 1.0, temporal.blend.z);
        result = history + (current - history) / count;
    }
#elif MODE_MOVING
    {
        // The neighbourhood: its statistics in YCoCg + coverage, and its nearest surface,
        // whose motion stands for the pixel's (silhouettes move with the object in front).
        vec4 sum = vec4(0.0), squares = vec4(0.0);
        float nearest = kInfinity, farthest = 0.0;
        ivec2 nearestTexel = pixel;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                ivec2 texel = clamp(pixel + ivec2(dx, dy), ivec2(0), size - 1);
                float d = dx == 0 && dy == 0 ? depth : imageLoad(inDepth, texel).r;
                vec4 value = dx == 0 && dy == 0 ? current : frameSample(texel, d);
                value.rgb = toYCoCg(value.rgb);
                sum += value;
                squares += value * value;
                if (d < nearest) {
                    nearest = d;
                    nearestTexel = texel;
                }
                farthest = isinf(d) ? farthest : max(farthest, d);
            }
        }
        // Off the surface the motion of the far plane stands in: the background is one colour.
        bool surface = !isinf(nearest);
        float reprojectedDepth = surface ? nearest : frame.depthRange.y;
        // The jittered texel's ray, and where that point sat in the previous un-jittered frame.
        vec3 position = viewPositionAt(vec2(nearestTexel) + 0.5, reprojectedDepth);
        vec3 previousPosition = (temporal.previousFromView * vec4(position, 1.0)).xyz;
        vec4 clip = temporal.previousProjection * vec4(previousPosition, 1.0);
        vec2 previousWindow =
            vec2(clip.x / clip.w + 1.0, 1.0 - clip.y / clip.w) * 0.5 * frame.viewport.xy;
        vec2 unjittered = vec2(nearestTexel) + 0.5 - frame.jitter.xy;
        vec2 source = vec2(pixel) + 0.5 + (previousWindow - unjittered) - 0.5;

        // Bilinear taps of the previous result, each kept only where it saw this surface.
        ivec2 first = ivec2(floor(source));
        vec2 t = source - vec2(first);
        float tolerance = temporal.depth.x + (surface ? farthest - nearest : 0.0);
        float expectedDepth = -previousPosition.z;
        vec4 history = vec4(0.0);
        float historyCount = 0.0, weightSum = 0.0;
        for (int tap = 0; tap < 4; ++tap) {
            ivec2 offset = ivec2(tap & 1, tap >> 1);
            ivec2 texel = first + offset;
            if (any(lessThan(texel, ivec2(0))) || any(greaterThanEqual(texel, size))) {
                continue;
            }
            vec2 state = imageLoad(inHistoryState, texel).rg;
            bool sameSurface = surface ? abs(state.r - expectedDepth) <= tolerance : true;
            if (!sameSurface) {
                continue;
            }
            vec2 axis = mix(1.0 - t, t, vec2(offset));
            float weight = axis.x * axis.y;
            history += weight * imageLoad(inHistory, texel);
            historyCount += weight * state.g;
            weightSum += weight;
        }
        // Below a tenth of the bilinear weight the history is mostly another surface's.
        if (weightSum > 0.1) {
            history /= weightSum;
            historyCount /= weightSum;
            vec4 mean = sum / 9.0;
            vec4 deviation = sqrt(max(squares / 9.0 - mean * mean, 0.0));
            vec4 clipped = clipToBox(vec4(toYCoCg(history.rgb), history.a), mean,
                                     temporal.blend.y * deviation);
            history = vec4(fromYCoCg(clipped.rgb), clipped.a);
            count = min(historyCount + 1.0, temporal.blend.z);
            result = mix(history, current, max(1.0 / count, temporal.blend.x));
        }
    }
#endif
    imageStore(outHistory, pixel, result);
    imageStore(outHistoryState, pixel, vec4(depth, count, 0.0, 0.0));
#if WRITE_PICTURE
    imageStore(outImage, pixel, vec4(linearToSrgb(result.rgb), 1.0));
#endif
}
