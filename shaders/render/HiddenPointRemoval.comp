#version 450
// Hidden point removal on the min-depth pyramid (paper §4; Pintus 2011, Bouchiba 2018).
// For a pixel holding a point x, in each of 8 directions look at the neighbouring texel on
// every level up to L(x) and keep the smallest
//     omega(x, y) = 1 - dot(normalize(y - x), normalize(-x)),
// i.e. the neighbour y that rises most towards the camera. x is visible when the mean of the 8
// smallest omegas reaches tau, or (the paper's edge rule) when 3 consecutive directions occlude
// while at least 3 others are open: x then lies just beyond an occluder's silhouette.
#include "shared/pyramid.glsl"
#include "shared/region.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_SURFACE) uniform SurfaceBlock {
    SurfaceParams surface;
};
layout(std430, binding = SUBSCAN_SSBO_PYRAMID) readonly buffer Pyramid {
    float minDepth[];
};
layout(binding = SUBSCAN_IMAGE_OUT0, r8) writeonly uniform image2D outVisibility;

const ivec2 kDirections[8] = ivec2[](ivec2(1, 0), ivec2(1, 1), ivec2(0, 1), ivec2(-1, 1),
                                     ivec2(-1, 0), ivec2(-1, -1), ivec2(0, -1), ivec2(1, -1));

// The pixels of this work group that hold a point, gathered so that the first invocations test
// them together: llvmpipe runs 8 invocations in lock-step, and on close-ups, where points are
// sparse and L(x) is large, most lanes would otherwise idle through their neighbours' walks.
shared uint occupied[gl_WorkGroupSize.x * gl_WorkGroupSize.y];
shared uint occupiedCount;

bool visibleAt(ivec2 pixel, float depth) {
    vec3 x = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toCamera = normalize(-x);
    float maxLevel = clamp(levelForRadius(surface.visibility.x, depth), 0.0,
                           float(levelCount() - 1u));
    uint levels = uint(maxLevel);
    float tau = surface.visibility.y;

    float omega[8];
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        // Branch-free: lanes in lock-step all take every step anyway. A missing neighbour
        // gives +inf, and a direction without any counts as open sideways (omega = 1).
        float smallest = kInfinity;
        LevelLayout place = levelLayout(0u);
        for (uint level = 0u; level <= levels; ++level, place = nextLevel(place)) {
            ivec2 texel = (pixel >> level) + kDirections[k];
            bool inside = insideLevel(place, texel);
            float neighbourDepth =
                minDepth[texelIndex(place, clamp(texel, ivec2(0), place.size - 1))];
            vec3 y = viewPositionAt(texelCentre(level, texel), neighbourDepth);
            float value = 1.0 - dot(normalize(y - x), toCamera);
            smallest = inside && !isinf(neighbourDepth) ? min(smallest, value) : smallest;
        }
        smallest = isinf(smallest) ? 1.0 : smallest;
        omega[k] = smallest;
        sum += smallest;
    }
    bool visible = sum / 8.0 >= tau;
    if (!visible && surface.visibility.z > 0.5) {
        int open = 0;
        for (int k = 0; k < 8; ++k) {
            open += omega[k] >= tau ? 1 : 0;
        }
        for (int k = 0; k < 8 && !visible; ++k) {
            bool run = omega[k] < tau && omega[(k + 1) % 8] < tau && omega[(k + 2) % 8] < tau;
            visible = run && open >= 3;
        }
    }
    return visible;
}

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        occupiedCount = 0u;
    }
    barrier();
    ivec2 pixel = dispatchTexel();
    if (insideLevel(0u, pixel)) {
        if (isinf(minDepth[texelIndex(0u, pixel)])) {
            imageStore(outVisibility, pixel, vec4(0.0));
        } else {
            occupied[atomicAdd(occupiedCount, 1u)] = gl_LocalInvocationIndex;
        }
    }
    barrier();
    if (gl_LocalInvocationIndex < occupiedCount) {
        uint local = occupied[gl_LocalInvocationIndex];
        ivec2 target = pixel - ivec2(gl_LocalInvocationID.xy) +
                       ivec2(local % gl_WorkGroupSize.x, local / gl_WorkGroupSize.x);
        bool visible = visibleAt(target, minDepth[texelIndex(0u, target)]);
        imageStore(outVisibility, target, vec4(visible ? 1.0 : 0.0));
    }
}
