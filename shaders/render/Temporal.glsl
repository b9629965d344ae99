// The temporal filter's blend (DESIGN.md §5 step 10), shared by Temporal.comp (its own pass,
// after shading or scattering) and FinishSurface.comp (the surface mode's fused end). The
// caller gives this frame's sample of a pixel, colour over the background and coverage (1 on
// the surface), and for a moving camera the statistics of its 3x3 neighbourhood; the result
// keeps both, and its state keeps this frame's depth (the next frame's disocclusion test) and
// how many frames the pixel's history holds.
//   still   the same camera as before: an even mean of up to blend.z frames, no clipping, so
//           the picture converges to the mean over the jitter pattern (a supersampled picture)
//   moving  the history fetched where the pixel's surface was in the previous frame; taps that
//           saw another surface there are dropped (disocclusion), and what is left is clipped
//           to the new frame's neighbourhood (variance clipping in YCoCg) before the blend
// Include after shared/common.glsl.

layout(std140, binding = SUBSCAN_UBO_TEMPORAL) uniform TemporalBlock {
    TemporalParams temporal;
};
// 32-bit floats: an even mean of n frames moves by (new - mean) / n, which half floats would
// round away once n reaches the hundreds.
layout(binding = SUBSCAN_IMAGE_IN2, rgba32f) readonly uniform image2D inHistory;
layout(binding = SUBSCAN_IMAGE_IN3, rg32f) readonly uniform image2D inHistoryState;
layout(binding = SUBSCAN_IMAGE_OUT2, rgba32f) writeonly uniform image2D outHistory;
layout(binding = SUBSCAN_IMAGE_OUT3, rg32f) writeonly uniform image2D outHistoryState;

vec3 toYCoCg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b,
                -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 fromYCoCg(vec3 c) { return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z); }

/// This frame's sample of a pixel of linear colour `radiance` and depth `depth`.
vec4 frameSample(vec3 radiance, float depth) {
    return isinf(depth) ? vec4(frame.background.rgb, 0.0) : vec4(radiance, 1.0);
}

/// Moves `history` towards `centre` until it lies inside the box centre ± extent.
vec4 clipToBox(vec4 history, vec4 centre, vec4 extent) {
    vec4 offset = history - centre;
    vec4 units = abs(offset) / max(extent, vec4(1e-6));
    float largest = max(max(units.x, units.y), max(units.z, units.w));
    return largest > 1.0 ? centre + offset / largest : history;
}

/// A still camera: the pixel's own history, an even mean over the jitter pattern. A history
/// built while moving (resampled, clipped) counts as one frame, so that what the motion left
/// fades as 1/n once the camera stops.
vec4 blendStill(ivec2 pixel, vec4 current, out float count) {
    vec4 history = imageLoad(inHistory, pixel);
    float frames = temporal.flags.x == 1u ? 1.0 : imageLoad(inHistoryState, pixel).g;
    count = min(frames + 1.0, temporal.blend.z);
    return history + (current - history) / count;
}

/// The new frame around a pixel: its samples' statistics in YCoCg + coverage, and its nearest
/// surface, whose motion stands for the pixel's (silhouettes move with the object in front).
struct Neighbourhood {
    vec4 sum;
    vec4 squares;
    float samples;
    float nearest;
    float farthest;
    ivec2 nearestTexel;
};

Neighbourhood emptyNeighbourhood(ivec2 pixel) {
    return Neighbourhood(vec4(0.0), vec4(0.0), 0.0, kInfinity, 0.0, pixel);
}

/// Adds the sample `value` (linear colour, coverage) at `texel` of depth `depth`; samples come
/// in row order, so ties keep the first.
void addSample(inout Neighbourhood around, ivec2 texel, vec4 value, float depth) {
    value.rgb = toYCoCg(value.rgb);
    around.sum += value;
    around.squares += value * value;
    around.samples += 1.0;
    if (depth < around.nearest) {
        around.nearest = depth;
        around.nearestTexel = texel;
    }
    around.farthest = isinf(depth) ? around.farthest : max(around.farthest, depth);
}

/// A moving camera: the previous result where the pixel's surface was, blended with
/// `current` (of depth `depth`); `current` alone where none of it saw this surface.
vec4 blendMoving(ivec2 pixel, vec4 current, float depth, Neighbourhood around, out float count) {
    ivec2 size = imageSizeOfFrame();
    count = 1.0;
    // Off the surface the motion of the far plane stands in: the background is one colour.
    bool surface = !isinf(around.nearest);
    float reprojectedDepth = surface ? around.nearest : frame.depthRange.y;
    // The jittered texel's ray, and where that point sat in the previous un-jittered frame.
    vec3 position = viewPositionAt(vec2(around.nearestTexel) + 0.5, reprojectedDepth);
    vec3 previousPosition = (temporal.previousFromView * vec4(position, 1.0)).xyz;
    vec4 clip = temporal.previousProjection * vec4(previousPosition, 1.0);
    vec2 previousWindow =
        vec2(clip.x / clip.w + 1.0, 1.0 - clip.y / clip.w) * 0.5 * frame.viewport.xy;
    vec2 unjittered = vec2(around.nearestTexel) + 0.5 - frame.jitter.xy;
    vec2 source = vec2(pixel) + 0.5 + (previousWindow - unjittered) - 0.5;

    // Bilinear taps of the previous result, each kept only where it saw this surface.
    ivec2 first = ivec2(floor(source));
    vec2 t = source - vec2(first);
    float tolerance = temporal.depth.x + (surface ? around.farthest - around.nearest : 0.0);
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
        // Background where background was is kept too (a silhouette's outer ring); clipping
        // then settles how much of the surface's edge it keeps.
        bool sameSurface = !surface || abs(state.r - expectedDepth) <= tolerance ||
                           (isinf(state.r) && isinf(depth));
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
    if (weightSum <= 0.1) {
        return current;
    }
    history /= weightSum;
    historyCount /= weightSum;
    vec4 mean = around.sum / around.samples;
    vec4 deviation = sqrt(max(around.squares / around.samples - mean * mean, 0.0));
    vec4 clipped =
        clipToBox(vec4(toYCoCg(history.rgb), history.a), mean, temporal.blend.y * deviation);
    history = vec4(fromYCoCg(clipped.rgb), clipped.a);
    count = min(historyCount + 1.0, temporal.blend.z);
    return mix(history, current, max(1.0 / count, temporal.blend.x));
}

void storeHistory(ivec2 pixel, vec4 result, float depth, float count) {
    imageStore(outHistory, pixel, result);
    imageStore(outHistoryState, pixel, vec4(depth, count, 0.0, 0.0));
}
