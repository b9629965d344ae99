// The shading model of Shade.comp, for it and FinishSurface.comp (which shades level 0 itself).
// An includer may define SHADE_DIRECTIONAL_LIGHTS 0 for frames with the head light alone: on
// llvmpipe the loop over the directional lights costs even when it runs zero times.
#include "shared/common.glsl"
#include "shared/lightmap.glsl"

#ifndef SHADE_DIRECTIONAL_LIGHTS
#define SHADE_DIRECTIONAL_LIGHTS 1
#endif

layout(std140, binding = SUBSCAN_UBO_PASS) uniform ShadeBlock {
    ShadeParams shade;
};

/// Bilinear percentage-closer test of light `light`'s map around texel position `texel`: each
/// of the 4 nearest texels is lit when its depth is not in front of the receiver's plane there
/// (depth `depth` at `texel`, `slope` per texel) by more than the tolerance.
float litFraction(uint light, vec2 texel, float depth, vec2 slope) {
    vec4 texels[4];
    vec2 f;
    lightMapTexels(light, shade.lightMap[light], texel, texels, f);
    vec4 stored = depthsOf(texels);
    vec4 dx = vec4(0.0, 1.0, 0.0, 1.0) - f.x;
    vec4 dy = vec4(0.0, 0.0, 1.0, 1.0) - f.y;
    // A texel holds the depth of its nearest point, anywhere inside it, or where it holds
    // none, what pull-push fills in from coarser levels biased towards the front: up to a
    // texel's slope in front of the plane's value at its centre.
    float tolerance = shade.shadow.x + abs(slope.x) + abs(slope.y);
    vec4 receiver = depth + slope.x * dx + slope.y * dy - tolerance;
    vec4 lit = vec4(greaterThanEqual(stored, receiver));
    return dot(lit, bilinearWeights(f));
}

/// The share of directional light `light` that reaches view-space `position` with surface
/// normal `normal` past the cloud's own surface, seen from the light (its light map): 4
/// bilinear percentage-closer tests, each texel compared with the receiver's tangent plane at
/// that texel (no acne on tilted surfaces) less the tolerance. A bilinear test fades over one
/// texel; the taps stand (width − 1 texel) apart, so that an edge fades over the soft edge's
/// width (ShadeParams.shadow.y), or one texel at the least.
float shadowing(uint light, vec3 position, vec3 normal) {
    vec4 map = shade.lightMap[light];
    vec3 at = lightMapPosition(shade.lightFromView[light], map, position);
    vec3 normalInLight = mat3(shade.lightFromView[light]) * normal;
    // Depth change per texel along the receiver's plane; the steepest 80 degrees.
    const float kSteepest = 5.67;
    vec2 slope = clamp(vec2(normalInLight.x, -normalInLight.y) / max(normalInLight.z, 1e-3),
                       -kSteepest, kSteepest) / map.x;
    float spread = 0.5 * max(shade.shadow.y * map.x - 1.0, 0.0);
    float lit = 0.0;
    for (int tap = 0; tap < 4; ++tap) {
        vec2 offset = spread * vec2(tap % 2 == 0 ? -1.0 : 1.0, tap < 2 ? -1.0 : 1.0);
        lit += litFraction(light, at.xy + offset, at.z + dot(slope, offset), slope);
    }
    return 0.25 * lit;
}

/// The irradiance of directional light `light` that entered where the light first meets the
/// cloud and diffused through it to view-space `position` (after Jimenez et al. 2010): the
/// entry's irradiance c cos θ_entry times the profile integrated over a plane t deep,
/// T(t) = Σ w_i e^(−t²/2v_i), t the distance to the entry's tangent plane (a plane-parallel
/// slab's thickness, whatever the light's angle). It fades in from one to three tolerances (the
/// shadows', at least a texel), so that the light's own first surface (t ≈ 0), which it lights
/// directly, gets none.
vec3 transmittedIrradiance(uint light, vec3 position) {
    vec4 map = shade.lightMap[light];
    vec3 at = lightMapPosition(shade.lightFromView[light], map, position);
    float tolerance = max(shade.shadow.x, 1.0 / map.x);
    vec3 entryNormal;
    float entryDepth =
        lightMapSurface(light, map, at.xy, lightMapJump(map, tolerance), entryNormal);
    float cosEntry = max(entryNormal.z, 0.0);  // the light travels along -z in its view
    float thickness = (at.z - entryDepth) * cosEntry;
    if (isinf(entryDepth) || !(thickness > tolerance)) {
        return vec3(0.0);
    }
    vec3 through = vec3(0.0);
    for (uint i = 0u; i < shade.profileCount.x; ++i) {
        through += shade.profile[i].rgb * exp(-thickness * thickness / (2.0 * shade.profile[i].w));
    }
    float fade = smoothstep(tolerance, 3.0 * tolerance, thickness);
    return shade.lightColor[light].rgb * cosEntry * fade * through;
}

void addLight(vec3 direction, vec3 radiance, vec3 normal, vec3 toEye, inout vec3 diffuse,
              inout vec3 specular) {
    float cosine = dot(normal, direction);
    if (cosine <= 0.0) {
        return;
    }
    vec3 halfway = normalize(direction + toEye);
    diffuse += radiance * cosine;
    specular += radiance * cosine * shade.specular.x *
                pow(max(dot(normal, halfway), 0.0), shade.specular.y);
}

/// The radiance leaving surface pixel `pixel` at `depth` towards the eye, by diffuse
/// reflection of `albedo` (0..1) and by specular reflection.
void shadePixel(ivec2 pixel, float depth, vec3 normal, vec3 albedo, out vec3 diffuse,
                out vec3 specular) {
    vec3 position = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toEye = normalize(-position);
    vec3 irradiance = shade.ambient.rgb;
    specular = vec3(0.0);
    addLight(toEye, shade.headLight.rgb, normal, toEye, irradiance, specular);
#if SHADE_DIRECTIONAL_LIGHTS
    for (uint i = 0u; i < shade.lightCount.x; ++i) {
        vec3 radiance = shade.lightColor[i].rgb;
        if (shade.lightMap[i].w > 0.0 && dot(normal, shade.lightDirection[i].xyz) > 0.0) {
            radiance *= shadowing(i, position, normal);
        }
        addLight(shade.lightDirection[i].xyz, radiance, normal, toEye, irradiance, specular);
        if (shade.profileCount.x > 0u) {
            irradiance += transmittedIrradiance(i, position);
        }
    }
#endif
    diffuse = albedo * irradiance;
}
