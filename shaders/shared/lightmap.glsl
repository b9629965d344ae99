// The directional lights' maps (LightMaps, LightMapPass): per light, rgba32f texels of its
// reconstruction seen from the light — the depth along the light (+inf where it meets nothing)
// and the surface normal in the light's view space. Shadows (render/Shade.glsl) and single
// scattering's entries (render/SingleScattering.comp) read them. Include after
// shared/common.glsl.

layout(binding = SUBSCAN_TEXTURES_LIGHT_MAPS) uniform sampler2D lightMaps[SUBSCAN_MAX_LIGHTS];

/// Where view-space `position` lies in a light's map (ShadeParams.lightFromView and .lightMap):
/// xy the continuous texel position (texel i spans [i, i + 1), row 0 at the top: the map's view
/// is centred on its axis), z the depth along the light.
vec3 lightMapPosition(mat4 lightFromView, vec4 map, vec3 position) {
    vec3 inLight = (lightFromView * vec4(position, 1.0)).xyz;
    return vec3(vec2(inLight.x, -inLight.y) * map.x + 0.5 * map.yz, -inLight.z);
}

#if SUBSCAN_MAX_LIGHTS != 4
#error "lightMapTexel reads 4 maps: give it a case for each light"
#endif

/// Texel `at` of light `light`'s map. A switch over constant indices rather than an indexed
/// sampler: llvmpipe turns a dynamically indexed sampler into a function call per read (single
/// scattering under a directional light: about a fifth faster).
vec4 lightMapTexel(uint light, ivec2 at) {
    switch (light) {
        case 0u:
            return texelFetch(lightMaps[0], at, 0);
        case 1u:
            return texelFetch(lightMaps[1], at, 0);
        case 2u:
            return texelFetch(lightMaps[2], at, 0);
        default:
            return texelFetch(lightMaps[3], at, 0);
    }
}

/// The 4 texels around continuous texel position `texel` of light `light`'s map — (0, 0),
/// (1, 0), (0, 1), (1, 1) from `base` = floor(texel - 0.5), clamped to the map, whose border is
/// empty — and the bilinear fraction `f`.
void lightMapTexels(uint light, vec4 map, vec2 texel, out vec4 texels[4], out vec2 f) {
    vec2 base = floor(texel - 0.5);
    f = texel - 0.5 - base;
    ivec2 last = ivec2(map.yz) - 1;
    for (int k = 0; k < 4; ++k) {
        ivec2 at = clamp(ivec2(base) + ivec2(k % 2, k / 2), ivec2(0), last);
        texels[k] = lightMapTexel(light, at);
    }
}

/// The weights of texels (0, 0), (1, 0), (0, 1), (1, 1) from lightMapTexels' `base` at
/// bilinear fraction `f`, and those texels' depths.
vec4 bilinearWeights(vec2 f) {
    return vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}
vec4 depthsOf(vec4 texels[4]) {
    return vec4(texels[0].r, texels[1].r, texels[2].r, texels[3].r);
}

/// The surface a light's map holds at continuous texel position `texel`: its depth along the
/// light, interpolated bilinearly where the 4 nearest texels hold one surface (their depths
/// within `jump` of each other), else the nearest texel's (+inf where that holds none), so that
/// no depth between an occluder and what lies behind it is made up; and the nearest texel's
/// normal (light view space).
float lightMapSurface(uint light, vec4 map, vec2 texel, float jump, out vec3 normal) {
    vec4 texels[4];
    vec2 f;
    lightMapTexels(light, map, texel, texels, f);
    vec4 weights = bilinearWeights(f);
    vec4 depths = depthsOf(texels);
    int nearest = 0;
    for (int k = 1; k < 4; ++k) {
        nearest = weights[k] > weights[nearest] ? k : nearest;
    }
    normal = texels[nearest].gba;
    float spread = max(max(depths.x, depths.y), max(depths.z, depths.w)) -
                   min(min(depths.x, depths.y), min(depths.z, depths.w));
    return spread <= jump ? dot(weights, depths) : depths[nearest];
}

/// The depth difference `lightMapSurface` still takes for one surface: the tolerance plus the
/// spread of a surface tilted 76 degrees from the light over a texel (4 texel widths).
float lightMapJump(vec4 map, float tolerance) { return tolerance + 4.0 / map.x; }
