// Helpers shared by the passes. Include after #version.
#include "shared/bindings.h"

layout(std140, binding = SUBSCAN_UBO_FRAME) uniform FrameBlock {
    FrameParams frame;
};

const float kInfinity = uintBitsToFloat(0x7F800000u);
const float kPi = 3.14159265358979;

ivec2 imageSizeOfFrame() { return ivec2(frame.viewport.xy); }

/// sRGB-encoded 0..1 -> linear (IEC 61966-2-1).
vec3 srgbToLinear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

/// linear 0..1 -> sRGB-encoded.
vec3 linearToSrgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

/// The window position (pixels, row 0 at the top) a view-space point projects to.
vec2 windowPosition(vec3 viewPosition) {
    vec4 clip = frame.projection * vec4(viewPosition, 1.0);
    vec2 ndc = clip.xy / clip.w;
    return vec2((ndc.x + 1.0) * 0.5, (1.0 - ndc.y) * 0.5) * frame.viewport.xy;
}

/// Projects a view-space point to its window position, the pixel containing it (row 0 at the
/// top) and its linear depth; false when it falls outside the image or the near/far range.
bool projectToWindow(vec3 viewPosition, out vec2 window, out ivec2 pixel, out float depth) {
    depth = -viewPosition.z;
    if (!(depth >= frame.depthRange.x && depth <= frame.depthRange.y)) {
        return false;
    }
    window = windowPosition(viewPosition);
    pixel = ivec2(floor(window));
    return all(greaterThanEqual(pixel, ivec2(0))) && all(lessThan(pixel, imageSizeOfFrame()));
}

/// projectToWindow without the window position.
bool projectToPixel(vec3 viewPosition, out ivec2 pixel, out float depth) {
    vec2 window;
    return projectToWindow(viewPosition, window, pixel, depth);
}

vec3 unpackColor(uint rgba8) { return srgbToLinear(unpackUnorm4x8(rgba8).rgb); }

/// What a length at linear depth `depth` is divided by to give its size in pixels / focal
/// length: the depth itself through a pinhole, 1 in an orthographic view (FrameParams).
float projectiveDepth(float depth) { return frame.depthRange.w > 0.0 ? 1.0 : depth; }

/// View-space position of a point seen at window position `window` (full-resolution pixels,
/// row 0 at the top; a pixel's centre is its index + 0.5) at linear depth `depth`; the inverse
/// of windowPosition(), jitter included.
vec3 viewPositionAt(vec2 window, float depth) {
    float focal = frame.depthRange.z;
    vec2 shifted = window - frame.jitter.xy;
    vec2 centred = vec2(shifted.x - 0.5 * frame.viewport.x, 0.5 * frame.viewport.y - shifted.y);
    return vec3(centred * (projectiveDepth(depth) / focal), -depth);
}

/// The pyramid level whose texels span `worldRadius` at `depth` (fractional, unclamped).
float levelForRadius(float worldRadius, float depth) {
    return log2(worldRadius * frame.depthRange.z / projectiveDepth(depth));
}

/// The unit direction from view-space `position` towards the eye: along +z in an
/// orthographic view, where every ray is parallel.
vec3 towardsEye(vec3 position) {
    return frame.depthRange.w > 0.0 ? vec3(0.0, 0.0, 1.0) : normalize(-position);
}

/// The unit normal packNormal (GpuPointCloud.h) stored as an octahedral snorm16x2, 0 for none.
vec3 unpackNormal(uint bits) {
    if (bits == 0u) {
        return vec3(0.0);
    }
    vec2 folded = unpackSnorm2x16(bits);
    vec3 normal = vec3(folded, 1.0 - abs(folded.x) - abs(folded.y));
    // The lower half was folded over the diagonals: unfold by the overshoot below z = 0.
    float below = max(-normal.z, 0.0);
    normal.xy += mix(vec2(below), vec2(-below), greaterThanEqual(normal.xy, vec2(0.0)));
    return normalize(normal);
}
