#!/usr/bin/env bash
# Mutation check of the temporal filter's tests: each deliberately wrong change to
# shaders/render/Temporal.glsl (the blend TemporalPass and FinishSurface share) or the jitter in
# shaders/shared/common.glsl (loaded through
# SUBSCAN_SHADER_DIR) must make TemporalGLTest fail. Prints one line per mutation and exits
# non-zero when a mutation survives. Needs a built tree (build/tests/TemporalGLTest).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mutation-check.sh
temporal=render/Temporal.glsl
common=shared/common.glsl

# name | shader | exact text | its wrong replacement
check_mutations build/tests/TemporalGLTest \
    "back-projection ignores the jitter|$common|    vec2 shifted = window - frame.jitter.xy;|    vec2 shifted = window;" \
    "velocity ignores the jitter|$temporal|vec2 unjittered = vec2(around.nearestTexel) + 0.5 - frame.jitter.xy;|vec2 unjittered = vec2(around.nearestTexel) + 0.5;" \
    "jitter added the wrong way|$temporal|vec2 unjittered = vec2(around.nearestTexel) + 0.5 - frame.jitter.xy;|vec2 unjittered = vec2(around.nearestTexel) + 0.5 + frame.jitter.xy;" \
    "history fetched half a pixel off|$temporal|vec2 source = vec2(pixel) + 0.5 + (previousWindow - unjittered) - 0.5;|vec2 source = vec2(pixel) + 0.5 + (previousWindow - unjittered);" \
    "window y not flipped|$temporal|vec2(clip.x / clip.w + 1.0, 1.0 - clip.y / clip.w)|vec2(clip.x / clip.w + 1.0, 1.0 + clip.y / clip.w)" \
    "the pixel's own motion, not its nearest neighbour's|$temporal|    if (depth < around.nearest) {|    if (around.samples == 5.0) {" \
    "no disocclusion|$temporal|abs(state.r - expectedDepth) <= tolerance|true" \
    "no clipping|$temporal|    history = vec4(fromYCoCg(clipped.rgb), clipped.a);|" \
    "YCoCg round trip wrong|$temporal|vec3 fromYCoCg(vec3 c) { return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z); }|vec3 fromYCoCg(vec3 c) { return vec3(c.x + c.y, c.x + c.z, c.x - c.y); }" \
    "bilinear weights swapped|$temporal|vec2 axis = mix(1.0 - t, t, vec2(offset));|vec2 axis = mix(t, 1.0 - t, vec2(offset));" \
    "still camera: exponential, not even|$temporal|    return history + (current - history) / count;|    return mix(history, current, 0.1);" \
    "still camera: no frame cap|$temporal|    count = min(frames + 1.0, temporal.blend.z);|    count = frames + 1.0;" \
    "motion's history weighed in full once still|$temporal|float frames = temporal.flags.x == 1u ? 1.0 : imageLoad(inHistoryState, pixel).g;|float frames = imageLoad(inHistoryState, pixel).g;" \
    "background counted as covered|$temporal|    return isinf(depth) ? vec4(frame.background.rgb, 0.0) : vec4(radiance, 1.0);|    return isinf(depth) ? vec4(frame.background.rgb, 1.0) : vec4(radiance, 1.0);"
