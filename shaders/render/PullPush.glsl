// Reads of the pull-push pyramids and the push step, for PullPush.comp and the passes after it
// (FinishSurface.comp pushes level 0 itself). The pyramids are written as storage buffers and
// read as buffer textures (see Buffer::bindTexels).
#include "shared/pyramid.glsl"
#include "shared/surface.glsl"

layout(binding = SUBSCAN_TEXELS_PULL_VALUES) uniform samplerBuffer pullValueTexels;
layout(binding = SUBSCAN_TEXELS_PULL_WEIGHTS) uniform samplerBuffer pullWeightTexels;
layout(binding = SUBSCAN_TEXELS_PULL_AXES) uniform samplerBuffer pullAxisTexels;
layout(binding = SUBSCAN_TEXELS_PUSH_VALUES) uniform samplerBuffer pushValueTexels;
layout(binding = SUBSCAN_TEXELS_NORMALS) uniform samplerBuffer normalTexels;

vec4 pullValueAt(uint index) { return texelFetch(pullValueTexels, int(index)); }
float pullWeightAt(uint index) { return texelFetch(pullWeightTexels, int(index)).r; }

/// The local spacing around `pixel` in units of h (1 without local spacing), for the fill's
/// expected gap and the normals' smoothing: a point's own, and for a pixel in a gap that of the
/// visible points in the finest texel above it that holds any or in that texel's parent,
/// whichever is larger: a gap between sparse points (a canopy) next to dense ones (the ground it
/// hides in part) must take the sparse points' spacing, and the finest texel often holds only
/// dense ones (measured on tests/gl/LocalSpacingGLTest.cpp's canopy: 115 pixels of background
/// left from the finest texel alone, 3 to 7 with its parent). Never below 1: where overlapping
/// strips or scans interleave, points lie closer than h but leave gaps of h between them
/// (autzen's meadow showed holes). spacingRatioFrom looks from `texel` on level `first` up.
float spacingRatioFrom(uint first, ivec2 texel) {
    if (surface.spacing.x < 0.5) {
        return 1.0;
    }
    for (uint level = first; level < levelCount(); ++level) {
        ivec2 above = texel >> (level - first);
        vec2 pulled = texelFetch(pullWeightTexels, int(texelIndex(level, above))).rg;
        if (pulled.x > 0.0) {
            float ratio = pulled.y / pulled.x;
            if (level > 0u && level + 1u < levelCount()) {
                vec2 parent =
                    texelFetch(pullWeightTexels, int(texelIndex(level + 1u, above >> 1))).rg;
                ratio = max(ratio, parent.y / parent.x);
            }
            return max(ratio, 1.0);
        }
    }
    return 1.0;
}
float spacingRatioAt(ivec2 pixel) { return spacingRatioFrom(0u, pixel); }

/// The mean across-lines axis (doubled angle, SUBSCAN_SSBO_ACROSS_LINES) of the visible points
/// in the finest texel above `texel` on level `first` that covers any; its length is how much
/// they agree and how much sparser their lines lie than the points along them (0 without local
/// spacing, or where no scan lines lie apart).
vec2 acrossAxisFrom(uint first, ivec2 texel) {
    if (surface.spacing.x < 0.5) {
        return vec2(0.0);
    }
    for (uint level = first; level < levelCount(); ++level) {
        vec4 sums = texelFetch(pullAxisTexels, int(texelIndex(level, texel >> (level - first))));
        if (sums.z > 0.0) {
            return sums.xy / sums.z;
        }
    }
    return vec2(0.0);
}
vec4 pushValueAt(uint index) { return texelFetch(pushValueTexels, int(index)); }

/// The complete (depth, r, g, b) of `texel` on `level` from the complete level above: m is the
/// bilinear of the coarser level with the kernel {1/4, 3/4, 3/4, 1/4}, and the texel's own
/// pulled value a with weight w keeps its share, a + (1 - w) * m.
vec4 pushedValue(uint level, ivec2 texel) {
    // Coarse neighbours of this texel and their weights {3/4, 1/4} per axis.
    ivec2 coarseSize = levelSize(level + 1u);
    ivec2 near = texel >> 1;
    ivec2 far = clamp(near + ((texel & 1) * 2 - 1), ivec2(0), coarseSize - 1);
    vec4 m = 0.5625 * pushValueAt(texelIndex(level + 1u, near)) +
             0.1875 * pushValueAt(texelIndex(level + 1u, ivec2(far.x, near.y))) +
             0.1875 * pushValueAt(texelIndex(level + 1u, ivec2(near.x, far.y))) +
             0.0625 * pushValueAt(texelIndex(level + 1u, far));
    // A fully weighted texel needs nothing from above (and an empty image above would give
    // 0 * inf = NaN).
    uint index = texelIndex(level, texel);
    float weight = pullWeightAt(index);
    vec4 own = pullValueAt(index);
    return weight >= 1.0 ? own : own + (1.0 - weight) * m;
}

/// With the points' own normals (SurfaceParams.normals.z): the complete view-space normal sum of
/// `texel` on `level` (levels below the coarsest), pushed as pushedValue pushes the values but
/// with the normals' own weight: the normal pyramid holds, pulled, (w_n * normal, w_n) per
/// texel, w_n the share of it that points with a normal cover, and from the coarsest level down
/// to level 1 the push overwrites each texel with its complete sum (the texel is the only one
/// that reads its own pulled value). Not unit length: the reader normalises.
vec3 pushedNormal(uint level, ivec2 texel) {
    ivec2 coarseSize = levelSize(level + 1u);
    ivec2 near = texel >> 1;
    ivec2 far = clamp(near + ((texel & 1) * 2 - 1), ivec2(0), coarseSize - 1);
    vec3 m = 0.5625 * texelFetch(normalTexels, int(texelIndex(level + 1u, near))).xyz +
             0.1875 * texelFetch(normalTexels, int(texelIndex(level + 1u, ivec2(far.x, near.y)))).xyz +
             0.1875 * texelFetch(normalTexels, int(texelIndex(level + 1u, ivec2(near.x, far.y)))).xyz +
             0.0625 * texelFetch(normalTexels, int(texelIndex(level + 1u, far))).xyz;
    vec4 own = texelFetch(normalTexels, int(texelIndex(level, texel)));
    return own.xyz + max(1.0 - own.w, 0.0) * m;
}
