#!/usr/bin/env bash
# Mutation check of the light maps' tests: each deliberately wrong change to the shadows,
# transmission or single scattering's entries (shaders/, loaded through SUBSCAN_SHADER_DIR)
# must make LightMapsGLTest fail. Prints one line per mutation and exits non-zero when a
# mutation survives. Needs a built tree (build/tests/LightMapsGLTest).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mutation-check.sh
shade=render/Shade.glsl
maps=shared/lightmap.glsl
single=render/SingleScattering.comp

# name | shader | exact text | its wrong replacement
check_mutations build/tests/LightMapsGLTest \
    "shadows ignore the map|$shade|            radiance *= shadowing(i, position, normal);|" \
    "no receiver plane|$shade|litFraction(light, at.xy + offset, at.z + dot(slope, offset), slope)|litFraction(light, at.xy + offset, at.z, vec2(0.0))" \
    "no slope in the tolerance|$shade|float tolerance = shade.shadow.x + abs(slope.x) + abs(slope.y);|float tolerance = shade.shadow.x;" \
    "taps half as far apart|$shade|float spread = 0.5 * max(shade.shadow.y * map.x - 1.0, 0.0);|float spread = 0.25 * shade.shadow.y * map.x;" \
    "light transformed with the wrong matrix|$maps|vec3 inLight = (lightFromView * vec4(position, 1.0)).xyz;|vec3 inLight = (transpose(lightFromView) * vec4(position, 1.0)).xyz;" \
    "map rows upside down|$maps|vec2(inLight.x, -inLight.y)|vec2(inLight.x, inLight.y)" \
    "bilinear weights swapped|$maps|f = texel - 0.5 - base;|f = 1.0 - (texel - 0.5 - base);" \
    "transmission along the slanted path|$shade|float thickness = (at.z - entryDepth) * cosEntry;|float thickness = at.z - entryDepth;" \
    "transmission fades without a floor|$shade|float tolerance = max(shade.shadow.x, 1.0 / map.x);|float tolerance = shade.shadow.x;" \
    "transmission without the entry's cosine|$shade|return shade.lightColor[light].rgb * cosEntry * fade * through;|return shade.lightColor[light].rgb * fade * through;" \
    "a constant entry tolerance|$single|float slack = max(lights.shadow.x - s * cosViewInside, 0.0);|float slack = lights.shadow.x;" \
    "no sample outside the medium|$single|entry.state = distanceAlong >= -slack ? kOutside : kInside;|entry.state = kOutside;" \
    "entry normal left in the light's view|$single|entry.normal = normalize(transpose(mat3(lights.lightFromView[light])) * normal);|entry.normal = normalize(normal);"
