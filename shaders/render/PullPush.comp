#version 450
// Pull-push interpolation (Kraus 2009) of depth and colour together, weighted by visibility.
//   STAGE_PULL_INIT  level 0: w = 1 for visible points, else 0; a = w * (depth, r, g, b); and
//                    beside w, w * the point's local spacing ratio ("color"'s alpha), pulled
//                    like the values but not pushed (PullPush.glsl's spacingRatioAt); and into
//                    "pullAxes" its across-lines axis ("acrossLines") and 1, summed on each
//                    level over the 2x2 children a texel covers that are on the front
//                    surface (FillRemoval.glsl's pointAcrossWithin)
//   STAGE_PULL       level R from R-1: W and A summed over the 4x4 children with the kernel
//                    h = {1/3, 1, 1, 1/3} per axis; w = min(1, W), a = A * w / W. Beyond
//                    Kraus: only children on the front-most surface take part (see below).
//   STAGE_PUSH_TOP   the coarsest level: complete value a / w
// With the points' own normals (SurfaceParams.normals.z) every stage does the same for them in
// the normal pyramid, with their own weight (PullPush.glsl's pushedNormal), except that the
// push stops at level 1: the normals' level 0 is pushed where it is read (Normals.glsl).
//   STAGE_PUSH       level R from R+1: m = bilinear of the complete coarser level with the
//                    kernel {1/4, 3/4, 3/4, 1/4}; complete = a + (1 - w) * m. Level 0 goes to
//                    the "filledDepth" and "filledColor" images instead of the buffer
//                    (unless FinishSurface.comp pushes it).
#include "render/PullPush.glsl"
#include "shared/region.glsl"
#include "shared/surface.glsl"

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(location = SUBSCAN_UNIFORM_LEVEL) uniform uint level;
layout(std430, binding = SUBSCAN_SSBO_PULL_VALUES) writeonly buffer PullValues {
    vec4 pullValue[];
};
layout(std430, binding = SUBSCAN_SSBO_PULL_WEIGHTS) writeonly buffer PullWeights {
    vec2 pullWeight[];  // w, w * local spacing ratio
};
layout(std430, binding = SUBSCAN_SSBO_PULL_AXES) writeonly buffer PullAxes {
    vec4 pullAxis[];  // sum of w * across-lines axis, sum of w, unused
};
layout(std430, binding = SUBSCAN_SSBO_PUSH_VALUES) writeonly buffer PushValues {
    vec4 pushValue[];
};
layout(std430, binding = SUBSCAN_SSBO_NORMALS) writeonly buffer NormalPyramid {
    vec4 normalPyramid[];  // pulled: w_n * normal, w_n; pushed: complete normal sum, 1
};
bool carriesNormals() { return surface.normals.z > 0.5; }
#if STAGE_PULL_INIT
layout(std430, binding = SUBSCAN_SSBO_ACROSS_LINES) readonly buffer AcrossLines {
    uint acrossLines[];
};
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inColor;
layout(binding = SUBSCAN_IMAGE_IN2, r8) readonly uniform image2D inVisibility;
layout(binding = SUBSCAN_IMAGE_IN3, rgba16f) readonly uniform image2D inPointNormal;
#endif
#if STAGE_PUSH
layout(binding = SUBSCAN_IMAGE_OUT0, r32f) writeonly uniform image2D outDepth;
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outColor;
#endif

const float kPullKernel[4] = float[](1.0 / 3.0, 1.0, 1.0, 1.0 / 3.0);

/// Whether child `c` of the 4x4 a pull reads (row-major from (-1, -1)) lies inside the texel.
bool coversChild(int c) { return (c % 4 == 1 || c % 4 == 2) && (c / 4 == 1 || c / 4 == 2); }

void main() {
    ivec2 texel = dispatchTexel();
    if (!insideLevel(level, texel) || !insideRegion(texel)) {
        return;
    }
    uint index = texelIndex(level, texel);
#if STAGE_PULL_INIT
    bool visible = imageLoad(inVisibility, texel).r > 0.5;
    // Only visible texels carry values: an empty texel's depth is +inf, and 0 * inf is NaN.
    vec4 color = imageLoad(inColor, texel);
    vec2 axis = visible && surface.spacing.x > 0.5
                    ? unpackHalf2x16(acrossLines[uint(texel.y) * uint(frame.viewport.x) +
                                                 uint(texel.x)])
                    : vec2(0.0);
    pullWeight[index] = visible ? vec2(1.0, color.a) : vec2(0.0);
    if (surface.spacing.x > 0.5) {
        pullAxis[index] = vec4(axis, visible ? 1.0 : 0.0, 0.0);
    }
    pullValue[index] = visible ? vec4(imageLoad(inDepth, texel).r, color.rgb) : vec4(0.0);
    if (carriesNormals()) {
        vec3 normal = visible ? imageLoad(inPointNormal, texel).xyz : vec3(0.0);
        normalPyramid[index] = vec4(normal, dot(normal, normal) > 0.0 ? 1.0 : 0.0);
    }
#elif STAGE_PULL
    // Only the front-most surface among the children: a child deeper than the nearest one by
    // more than `slope` texel widths (at that depth) belongs to a surface behind and is left out.
    // Plain pull-push would blend both, and at an occluder's edge fill its gaps with depths from
    // behind it; a surface steeper than the slope (atan 8 = 83 degrees by default) is cut.
    // The 16 children are read once into registers; both loops below are unrolled.
    float weights[16];
    float spacings[16];
    // The across-lines sums of the 2x2 children this texel covers (a quarter of the reads: the
    // axis only steers the reach beyond a sparse surface's outermost points).
    vec4 axes[16];
    bool localSpacing = surface.spacing.x > 0.5;
    vec4 values[16];
    float depths[16];
    float front = kInfinity;
    for (int c = 0; c < 16; ++c) {
        // Branch-free, clamped reads: lanes in lock-step would take both sides anyway.
        ivec2 child = 2 * texel + ivec2(c % 4 - 1, c / 4 - 1);
        uint childIndex =
            texelIndex(level - 1u, clamp(child, ivec2(0), levelSize(level - 1u) - 1));
        vec2 pulled = texelFetch(pullWeightTexels, int(childIndex)).rg;
        float weight = insideLevel(level - 1u, child) ? pulled.x : 0.0;
        spacings[c] = weight > 0.0 ? pulled.y : 0.0;
        axes[c] = coversChild(c) && weight > 0.0 && localSpacing
                      ? texelFetch(pullAxisTexels, int(childIndex))
                      : vec4(0.0);
        vec4 value = pullValueAt(childIndex);
        weights[c] = weight;
        values[c] = weight > 0.0 ? value : vec4(0.0);
        depths[c] = weight > 0.0 ? value.x / weight : kInfinity;
        front = min(front, depths[c]);
    }
    float tolerance = surface.fill.z * float(1u << level) * projectiveDepth(front) /
                      frame.depthRange.z;
    float weightSum = 0.0;
    float spacingSum = 0.0;
    vec4 axisSum = vec4(0.0);
    vec4 valueSum = vec4(0.0);
    vec4 normalSum = vec4(0.0);
    bool normals = carriesNormals();
    for (int c = 0; c < 16; ++c) {
        if (weights[c] > 0.0 && depths[c] <= front + tolerance) {
            float h = kPullKernel[c % 4] * kPullKernel[c / 4];
            weightSum += h * weights[c];
            spacingSum += h * spacings[c];
            axisSum += axes[c];
            valueSum += h * values[c];
            if (normals) {
                ivec2 child = 2 * texel + ivec2(c % 4 - 1, c / 4 - 1);
                normalSum += h * texelFetch(normalTexels, int(texelIndex(level - 1u, child)));
            }
        }
    }
    float clamped = min(1.0, weightSum);
    float scale = weightSum > 0.0 ? clamped / weightSum : 0.0;
    pullWeight[index] = vec2(clamped, spacingSum * scale);
    if (localSpacing) {
        pullAxis[index] = axisSum;
    }
    pullValue[index] = valueSum * scale;
    if (normals) {
        float normalWeight = min(1.0, normalSum.w);
        normalPyramid[index] = normalSum.w > 0.0 ? normalSum * (normalWeight / normalSum.w)
                                                 : vec4(0.0);
    }
#elif STAGE_PUSH_TOP
    float weight = pullWeightAt(index);
    pushValue[index] = weight > 0.0 ? pullValueAt(index) / weight : vec4(kInfinity, 0.0, 0.0, 0.0);
    if (carriesNormals()) {
        vec4 pulled = texelFetch(normalTexels, int(index));
        normalPyramid[index] = vec4(pulled.w > 0.0 ? pulled.xyz / pulled.w : vec3(0.0), 1.0);
    }
#else
    vec4 complete = pushedValue(level, texel);
    // Level 0 lives only in the images: nothing reads it from the buffer.
    if (level == 0u) {
        imageStore(outDepth, texel, vec4(complete.x));
        imageStore(outColor, texel, vec4(complete.yzw, 1.0));
    } else {
        pushValue[index] = complete;
        if (carriesNormals()) {
            normalPyramid[index] = vec4(pushedNormal(level, texel), 1.0);
        }
    }
#endif
}
