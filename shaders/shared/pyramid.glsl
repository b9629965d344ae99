// Image pyramids stored level after level in one storage buffer (see PyramidLayout).
#include "shared/common.glsl"

layout(std140, binding = SUBSCAN_UBO_PYRAMID) uniform PyramidBlock {
    PyramidLayout pyramid;
};

uint levelCount() { return pyramid.info.x; }
ivec2 levelSize(uint level) { return ivec2(pyramid.levels[level].yz); }
bool insideLevel(uint level, ivec2 texel) {
    return all(greaterThanEqual(texel, ivec2(0))) && all(lessThan(texel, levelSize(level)));
}
uint texelIndex(uint level, ivec2 texel) {
    return pyramid.levels[level].x + uint(texel.y) * pyramid.levels[level].y + uint(texel.x);
}
/// Centre of a level texel in full-resolution window coordinates.
vec2 texelCentre(uint level, ivec2 texel) { return (vec2(texel) + 0.5) * float(1u << level); }

/// The four texels of `level` around full-resolution window position `window` and their
/// bilinear weights (texel centres as sample points, clamped at the borders).
void bilinearTexels(uint level, vec2 window, out ivec2 texels[4], out float weights[4]) {
    vec2 position = window / float(1u << level) - 0.5;
    vec2 base = floor(position);
    vec2 t = position - base;
    ivec2 maxTexel = levelSize(level) - 1;
    ivec2 b = ivec2(base);
    texels[0] = clamp(b, ivec2(0), maxTexel);
    texels[1] = clamp(b + ivec2(1, 0), ivec2(0), maxTexel);
    texels[2] = clamp(b + ivec2(0, 1), ivec2(0), maxTexel);
    texels[3] = clamp(b + ivec2(1, 1), ivec2(0), maxTexel);
    weights[0] = (1.0 - t.x) * (1.0 - t.y);
    weights[1] = t.x * (1.0 - t.y);
    weights[2] = (1.0 - t.x) * t.y;
    weights[3] = t.x * t.y;
}
