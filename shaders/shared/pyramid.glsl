// Image pyramids stored level after level in one storage buffer (see PyramidLayout).
#include "shared/common.glsl"

layout(std140, binding = SUBSCAN_UBO_PYRAMID) uniform PyramidBlock {
    PyramidLayout pyramid;
};

uint levelCount() { return pyramid.info.x; }

/// A texel's 8 neighbours, counter-clockwise from +x: the directions the hidden point test and
/// fill removal look in.
const ivec2 kDirections[8] = ivec2[](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1),
                                     ivec2(-1, 0), ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

/// One level's place in the buffer. Loops over levels derive each level's place from the one
/// below (nextLevel): where the level is not a uniform, every read of the layout block is a
/// gather (on llvmpipe, a load per invocation).
struct LevelLayout {
    uint first;
    ivec2 size;
};
LevelLayout levelLayout(uint level) {
    uvec4 entry = pyramid.levels[level];
    return LevelLayout(entry.x, ivec2(entry.yz));
}
/// The level above `below`, laid out as PyramidLayout does (render/Pyramid.cpp).
LevelLayout nextLevel(LevelLayout below) {
    return LevelLayout(below.first + uint(below.size.x * below.size.y), (below.size + 1) >> 1);
}
bool insideLevel(LevelLayout place, ivec2 texel) {
    return all(greaterThanEqual(texel, ivec2(0))) && all(lessThan(texel, place.size));
}
uint texelIndex(LevelLayout place, ivec2 texel) {
    return place.first + uint(texel.y) * uint(place.size.x) + uint(texel.x);
}

ivec2 levelSize(uint level) { return levelLayout(level).size; }
bool insideLevel(uint level, ivec2 texel) { return insideLevel(levelLayout(level), texel); }
uint texelIndex(uint level, ivec2 texel) { return texelIndex(levelLayout(level), texel); }

/// Centre of a level texel in full-resolution window coordinates.
vec2 texelCentre(uint level, ivec2 texel) { return (vec2(texel) + 0.5) * float(1u << level); }

/// The four texels of `level` (laid out as `place`) around full-resolution window position
/// `window` and their bilinear weights (texel centres as sample points, clamped at the borders).
void bilinearTexels(uint level, LevelLayout place, vec2 window, out ivec2 texels[4],
                    out float weights[4]) {
    vec2 position = window / float(1u << level) - 0.5;
    vec2 base = floor(position);
    vec2 t = position - base;
    ivec2 maxTexel = place.size - 1;
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
