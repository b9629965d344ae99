#version 450
// Single scattering in screen space (DESIGN.md §6.3, §6.4; the paper's §5.1.1 and §5.2).
// Per surface pixel: the view ray refracted into the surface is sampled; from each sample a
// march towards each light through the reconstructed depth finds where that light entered; the
// light scattered once towards the eye is summed with Fresnel transmission at both ends, the
// Henyey-Greenstein phase function, extinction on both legs, the refracted beam's compression
// and 1/η² on leaving. σs and σa come from the material, or per pixel from the colour (the
// colour taken as total diffuse reflectance, inverted through a table, and the mean free path).
// The estimator is the CPU's estimateSingleScattering (sss/SingleScattering.h) with midpoint
// strata.
//   STAGE_RADIANCE_*   "scatteredRadiance" = "radiance" (diffuse + specular) + single
//   STAGE_SCATTERED_*  "scatteredRadiance" += single (after the Gaussian blur)
// Frames that export (params.flags.y) also write "singleScattering" alone and σs′, σa (mm⁻¹)
// per pixel.
#include "shared/common.glsl"
#include "shared/region.glsl"

// The stages come in threes by what they add to (RADIANCE_*, SCATTERED_*): *_HEAD_LIGHT for
// frames lit by the head light alone (the directional lights' loop costs on llvmpipe even
// when it runs zero times), *_LIGHTS with the loop marching through the camera's depth, and
// *_LIGHT_MAPS with the loop reading each light's entries from its light map.
#ifdef STAGE_SCATTERED_HEAD_LIGHT
#define ADD_TO_SCATTERED 1
#define DIRECTIONAL_LIGHTS (STAGE_SCATTERED_LIGHTS || STAGE_SCATTERED_LIGHT_MAPS)
#define LIGHT_MAP_ENTRIES STAGE_SCATTERED_LIGHT_MAPS
#else
#define ADD_TO_SCATTERED 0
#define DIRECTIONAL_LIGHTS (STAGE_RADIANCE_LIGHTS || STAGE_RADIANCE_LIGHT_MAPS)
#define LIGHT_MAP_ENTRIES STAGE_RADIANCE_LIGHT_MAPS
#endif
#if LIGHT_MAP_ENTRIES
#include "shared/lightmap.glsl"
#endif

layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
layout(std140, binding = SUBSCAN_UBO_PASS) uniform SingleScatterBlock {
    SingleScatterParams params;
};
layout(std140, binding = SUBSCAN_UBO_LIGHTS) uniform LightBlock {
    ShadeParams lights;
};
layout(binding = SUBSCAN_TEXELS_ALBEDO_ROOTS) uniform samplerBuffer albedoRoots;
layout(binding = SUBSCAN_IMAGE_IN0, r32f) readonly uniform image2D inSurfaceDepth;
layout(binding = SUBSCAN_IMAGE_IN1, rgba16f) readonly uniform image2D inNormals;
layout(binding = SUBSCAN_IMAGE_IN2, rgba16f) readonly uniform image2D inAlbedo;
#if ADD_TO_SCATTERED
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) uniform image2D scatteredRadiance;  // in place
#else
layout(binding = SUBSCAN_IMAGE_IN3, rgba16f) readonly uniform image2D inRadiance;
layout(binding = SUBSCAN_IMAGE_OUT0, rgba16f) writeonly uniform image2D scatteredRadiance;
#endif
layout(binding = SUBSCAN_IMAGE_OUT1, rgba16f) writeonly uniform image2D outSingle;
layout(binding = SUBSCAN_IMAGE_OUT2, rgba32f) writeonly uniform image2D outSigmaSPrime;
layout(binding = SUBSCAN_IMAGE_OUT3, rgba32f) writeonly uniform image2D outSigmaA;

// The march looks for the entry up to where the light is down to e^-6 (0.25 %) of itself.
const float kExtinctionDepths = 6.0;
const int kRefinements = 8;  // bisections of the step that crossed the surface, at most

float refractedCosine(float cosine, float eta) {
    float sine2 = max(0.0, 1.0 - cosine * cosine) / (eta * eta);
    return sqrt(max(0.0, 1.0 - sine2));
}

/// The direction refracted into the medium, still pointing out of the surface.
vec3 refractedDirection(vec3 direction, vec3 normal, float eta) {
    float cosine = dot(direction, normal);
    return (direction - cosine * normal) / eta + refractedCosine(cosine, eta) * normal;
}

float fresnelTransmittance(float cosine, float eta) {
    float cosOutside = clamp(abs(cosine), 0.0, 1.0);
    float cosInside = refractedCosine(cosOutside, eta);
    float perpendicular = (cosOutside - eta * cosInside) / (cosOutside + eta * cosInside);
    float parallel = (eta * cosOutside - cosInside) / (eta * cosOutside + cosInside);
    return 1.0 - 0.5 * (perpendicular * perpendicular + parallel * parallel);
}

float henyeyGreenstein(float cosine, float g) {
    float denominator = 1.0 + g * g - 2.0 * g * cosine;
    return (1.0 - g * g) / (4.0 * kPi * denominator * sqrt(denominator));
}

/// √(1 − α′) of the medium whose total diffuse reflectance is `reflectance` (linear
/// interpolation in the table; reflectances past its last entry take that entry's).
float albedoRoot(float reflectance) {
    float last = params.sampling.y - 1.0;
    float position = clamp(reflectance / params.sampling.z, 0.0, 1.0) * last;
    int lower = min(int(position), int(last) - 1);
    float fraction = position - float(lower);
    return mix(texelFetch(albedoRoots, lower).r, texelFetch(albedoRoots, lower + 1).r, fraction);
}

/// What the depth buffer says of a point: whether it lies inside the surface shown at its
/// pixel (below that pixel's tangent plane: exact for a plane, first order elsewhere), outside
/// it, hidden (more than a thickness behind it: that pixel shows another, nearer object) or off
/// the image; and that pixel's surface point and normal.
struct Probe {
    int state;
    ivec2 pixel;
    vec3 surfacePoint;
    vec3 normal;
};

const int kInside = 0;
const int kOutside = 1;
const int kHidden = 2;
const int kOffScreen = 3;

Probe probe(vec3 q, float thickness) {
    Probe result;
    result.surfacePoint = vec3(0.0);
    result.normal = vec3(0.0);
    float depth;
    if (!projectToPixel(q, result.pixel, depth)) {
        result.state = kOffScreen;
        return result;
    }
    float front = imageLoad(inSurfaceDepth, result.pixel).r;
    if (isinf(front)) {
        result.state = kOutside;
        return result;
    }
    result.surfacePoint = viewPositionAt(vec2(result.pixel) + 0.5, front);
    result.normal = imageLoad(inNormals, result.pixel).xyz;
    if (depth - front > thickness) {
        result.state = kHidden;
    } else {
        result.state = dot(result.normal, q - result.surfacePoint) < 0.0 ? kInside : kOutside;
    }
    return result;
}

/// How far along `toLight` from `start` the tangent plane of `inside` is crossed.
float planeCrossing(vec3 start, vec3 toLight, Probe inside) {
    return dot(inside.normal, inside.surfacePoint - start) / dot(inside.normal, toLight);
}

/// Where a light entered on its way to a sample: the straight distance, the surface's normal
/// there, and whether it was found.
struct Entry {
    int state;  // kOutside: found; kInside: none within reach (extinct); kOffScreen: unknown
    float distance;
    vec3 normal;
};

/// Whether `q` lies inside, by its probe; where the probe's pixel shows a nearer object, by
/// the tangent plane of the last pixel that showed ours (`last`): the surface is taken to go on
/// as it was behind the other object, so that object casts nothing on ours.
bool insideAlong(vec3 q, Probe here, Probe last) {
    if (here.state == kHidden) {
        return dot(last.normal, q - last.surfacePoint) < 0.0;
    }
    return here.state == kInside;
}

/// Marches from `start` (inside, `reach` below the surface along the view ray, seen as
/// `startProbe`) towards a directional light along `toLight`, about a pixel a step, for at most
/// `length`; refines the crossing by bisection until both ends share a pixel, then solves the
/// tangent plane of the last pixel inside.
Entry marchToLight(vec3 start, Probe startProbe, float reach, vec3 toLight, float length,
                   float thicknessScale) {
    Entry entry;
    entry.state = kInside;
    entry.distance = 0.0;
    entry.normal = vec3(0.0);
    if (toLight.z > 0.0) {
        // Stay behind the near plane, where points still project.
        length = min(length, 0.999 * (-start.z - frame.depthRange.x) / toLight.z);
    }
    float screenLength = distance(windowPosition(start), windowPosition(start + length * toLight));
    int steps = clamp(int(ceil(screenLength)), 1, int(params.sampling.w));
    float step = length / float(steps);
    float inside = 0.0;
    float outside = -1.0;
    Probe insideProbe = startProbe;
    for (int i = 1; i <= steps; ++i) {
        float along = float(i) * step;
        vec3 q = start + along * toLight;
        Probe here = probe(q, thicknessScale * (reach + along));
        if (here.state == kOffScreen) {
            entry.state = kOffScreen;
            return entry;
        }
        if (!insideAlong(q, here, insideProbe)) {
            outside = along;
            break;
        }
        inside = along;
        insideProbe = here.state == kInside ? here : insideProbe;
    }
    if (outside < 0.0) {
        return entry;
    }
    for (int i = 0; i < kRefinements; ++i) {
        ivec2 outsidePixel;
        float outsideDepth;
        projectToPixel(start + outside * toLight, outsidePixel, outsideDepth);
        if (outsidePixel == insideProbe.pixel) {
            break;
        }
        float middle = 0.5 * (inside + outside);
        vec3 q = start + middle * toLight;
        Probe here = probe(q, thicknessScale * (reach + middle));
        if (insideAlong(q, here, insideProbe)) {
            inside = middle;
            insideProbe = here.state == kInside ? here : insideProbe;
        } else {
            outside = middle;
        }
    }
    float crossing = planeCrossing(start, toLight, insideProbe);
    entry.state = kOutside;
    entry.distance = isnan(crossing) ? inside : clamp(crossing, inside, outside);
    entry.normal = insideProbe.normal;
    return entry;
}

/// The flat slab of the local tangent plane (normal `normal`), where the depth buffer cannot
/// tell where the light entered: the sample lies s cos θo′ below the plane, which lightThrough
/// turns into the refracted path s cos θo′ / cos θi′.
Entry localSlabEntry(float s, vec3 toLight, vec3 normal, float cosView) {
    Entry entry;
    entry.normal = normal;
    float cosIn = dot(normal, toLight);
    entry.state = cosIn > 0.0 ? kOutside : kInside;
    entry.distance = cosIn > 0.0 ? s * refractedCosine(cosView, params.medium.x) / cosIn : 0.0;
    return entry;
}

#if LIGHT_MAP_ENTRIES
/// Where directional light `light` entered on its way to `samplePoint`, from its light map:
/// the first surface the light meets above the sample (lightMapSurface), at the straight
/// distance between them along the light less `registration` (lightMapRegistration), with that
/// surface's normal. kInside (no light) where the sample lies in front of that surface by more
/// than the tolerance `slack` — outside the medium as the light sees it, e.g. past the far face
/// of a thin part —, kOffScreen where the map holds no surface.
Entry lightMapEntry(uint light, vec3 samplePoint, float slack, float registration) {
    Entry entry;
    vec4 map = lights.lightMap[light];
    vec3 at = lightMapPosition(lights.lightFromView[light], map, samplePoint);
    vec3 normal;
    float surfaceDepth =
        lightMapSurface(light, map, at.xy, lightMapJump(map, lights.shadow.x), normal);
    if (isinf(surfaceDepth)) {
        entry.state = kOffScreen;
        entry.distance = 0.0;
        entry.normal = vec3(0.0);
        return entry;
    }
    // Light view -> camera view: the inverse of a rotation is its transpose.
    entry.normal = normalize(transpose(mat3(lights.lightFromView[light])) * normal);
    float distanceAlong = at.z - surfaceDepth - registration;
    entry.state = distanceAlong >= -slack ? kOutside : kInside;
    entry.distance = max(distanceAlong, 0.0);
    return entry;
}

/// How far the camera's reconstruction of this pixel's surface (`surfacePoint`, `normal`) lies
/// behind light `light`'s reconstruction of it, along the light, where both show one surface.
/// Each view takes a pixel's (texel's) depth from its nearest point, anywhere inside it: a
/// surface tilted to the view comes out up to that pixel's depth slope in front of the truth,
/// differently in the two views, and under a close camera that is a good part of a mean free
/// path (a marble plate seen at 60 degrees and lit head-on came out 28 % too bright). The
/// entries are measured from the camera's surface, as the samples are. None where the pixel
/// lies farther from the light's surface than both slopes and the shadows' tolerance (it is in
/// shadow, or the light enters elsewhere, e.g. through a thin part's far face): the
/// registration fades out between one and two such widths.
float lightMapRegistration(uint light, vec3 surfacePoint, vec3 normal, float pixelSize) {
    vec3 toLight = lights.lightDirection[light].xyz;
    float cosIn = dot(normal, toLight);
    if (!(cosIn > 0.0)) {
        return 0.0;
    }
    vec4 map = lights.lightMap[light];
    vec3 at = lightMapPosition(lights.lightFromView[light], map, surfacePoint);
    vec3 mapNormal;
    float surfaceDepth =
        lightMapSurface(light, map, at.xy, lightMapJump(map, lights.shadow.x), mapNormal);
    if (isinf(surfaceDepth)) {
        return 0.0;
    }
    // The depth slope over a pixel (texel) in each view, as a distance from the plane, then
    // along the light; the steepest 78 degrees.
    vec3 normalInLight = mat3(lights.lightFromView[light]) * normal;
    float slopes = pixelSize * (abs(normal.x) + abs(normal.y)) +
                   (abs(normalInLight.x) + abs(normalInLight.y)) / map.x;
    float width = lights.shadow.x + slopes / max(cosIn, 0.2);
    float offset = at.z - surfaceDepth;
    return offset * (1.0 - smoothstep(width, 2.0 * width, abs(offset)));
}
#endif

struct Medium {
    vec3 sigmaS;  // unreduced, per scene unit
    vec3 sigmaT;  // per scene unit
};

/// The light of value `color` from `toLight` that entered at `entry` and reaches the sample,
/// per channel, before σs e^(−σt s) and the exit terms: p T_i (cos θi / cos θi′) E
/// e^(−σt s_i′), s_i′ = s_i cos θi / cos θi′ (DESIGN.md §6.3).
vec3 lightThrough(Entry entry, vec3 toLight, vec3 color, vec3 eyeInside, Medium medium) {
    if (entry.state != kOutside) {
        return vec3(0.0);
    }
    float eta = params.medium.x;
    float approach = dot(entry.normal, toLight);
    float cosIn = abs(approach);
    if (!(cosIn > 0.0)) {
        return vec3(0.0);
    }
    vec3 entryNormal = approach >= 0.0 ? entry.normal : -entry.normal;
    float cosInInside = refractedCosine(cosIn, eta);
    float lightPath = entry.distance * cosIn / cosInInside;
    vec3 lightInside = refractedDirection(toLight, entryNormal, eta);
    float phase = henyeyGreenstein(-dot(lightInside, eyeInside), params.medium.y);
    float weight = phase * fresnelTransmittance(cosIn, eta) * cosIn / cosInInside * kPi;
    return weight * color * exp(-medium.sigmaT * lightPath);
}

void main() {
    ivec2 pixel = dispatchTexel();
    if (any(greaterThanEqual(pixel, imageSizeOfFrame())) || !insideRegion(pixel)) {
        return;
    }
    float depth = imageLoad(inSurfaceDepth, pixel).r;
#if ADD_TO_SCATTERED
    vec4 base = imageLoad(scatteredRadiance, pixel);
#else
    vec4 base = imageLoad(inRadiance, pixel);
#endif
    bool exports = params.flags.y != 0u;
    if (isinf(depth)) {
        if (exports) {
            imageStore(outSingle, pixel, vec4(0.0));
            imageStore(outSigmaSPrime, pixel, vec4(0.0));
            imageStore(outSigmaA, pixel, vec4(0.0));
        }
        imageStore(scatteredRadiance, pixel, base);
        return;
    }
    float eta = params.medium.x;
    float g = params.medium.y;
    vec3 sigmaSPrime = params.sigmaSPrime.rgb;
    vec3 sigmaA = params.sigmaA.rgb;
    if (params.flags.x != 0u) {
        // DESIGN.md §6.4 with u = √(1 − α′): σt′ = σtr/(√3 u), σs′ = α′σt′ and
        // σa = σt′ − σs′ = σtr u/√3, written so that no difference of near-equal terms loses
        // a bright colour's small σa.
        vec3 albedo = clamp(imageLoad(inAlbedo, pixel).rgb, 0.0, 1.0);
        vec3 root = vec3(albedoRoot(albedo.r), albedoRoot(albedo.g), albedoRoot(albedo.b));
        vec3 effectiveExtinction = 1.0 / params.meanFreePath.rgb;
        sigmaSPrime = (1.0 - root * root) * effectiveExtinction / (sqrt(3.0) * root);
        sigmaA = effectiveExtinction * root / sqrt(3.0);
    }
    if (exports) {
        imageStore(outSigmaSPrime, pixel, vec4(sigmaSPrime, 1.0));
        imageStore(outSigmaA, pixel, vec4(sigmaA, 1.0));
    }

    Medium medium;
    medium.sigmaS = sigmaSPrime / (1.0 - g) * params.medium.z;
    medium.sigmaT = max(medium.sigmaS + sigmaA * params.medium.z, vec3(1e-30));

    vec3 normal = normalize(imageLoad(inNormals, pixel).xyz);
    vec3 surfacePoint = viewPositionAt(vec2(pixel) + 0.5, depth);
    vec3 toEye = normalize(-surfacePoint);
    float cosView = dot(normal, toEye);
    vec3 single = vec3(0.0);
    if (cosView > 0.0 && any(greaterThan(medium.sigmaS, vec3(0.0)))) {
        vec3 eyeInside = refractedDirection(toEye, normal, eta);
        float cosViewInside = dot(eyeInside, normal);
        float sigmaTMin = min(medium.sigmaT.r, min(medium.sigmaT.g, medium.sigmaT.b));
        int samples = int(params.sampling.x);
        ivec3 channelSamples = (ivec3(samples + 2) - ivec3(0, 1, 2)) / 3;
        float thicknessScale = 2.0 / max(cosView, 0.2);
#if LIGHT_MAP_ENTRIES
        float registration[SUBSCAN_MAX_LIGHTS];
        float pixelSize = projectiveDepth(depth) / frame.depthRange.z;
        for (uint i = 0u; i < lights.lightCount.x; ++i) {
            registration[i] = lightMapRegistration(i, surfacePoint, normal, pixelSize);
        }
#endif
        for (int k = 0; k < samples; ++k) {
            int channel = k % 3;
            float xi = (float(k / 3) + 0.5) / float(channelSamples[channel]);
            float s = -log(1.0 - xi) / medium.sigmaT[channel];
            vec3 viewExtinction = exp(-medium.sigmaT * s);
            // Σ_j n_j σt_j e^(−σt_j s): the channels' free-path densities, combined.
            float density = dot(vec3(channelSamples) * medium.sigmaT, viewExtinction);
            vec3 samplePoint = surfacePoint - s * eyeInside;
            Probe sampleProbe = probe(samplePoint, thicknessScale * s);
            if (sampleProbe.state == kOutside) {
                continue;  // the refracted ray left the medium: nothing scatters there
            }
            bool local = sampleProbe.state != kInside;
            vec3 light = vec3(0.0);
            // The head light's path to the sample lies on the sample's own line of sight, so
            // it entered through the surface of the sample's pixel: no march.
            vec3 toHead = normalize(-samplePoint);
            Entry headEntry;
            if (local) {
                headEntry = localSlabEntry(s, toHead, normal, cosView);
            } else {
                headEntry.normal = sampleProbe.normal;
                headEntry.distance = planeCrossing(samplePoint, toHead, sampleProbe);
                headEntry.state = headEntry.distance >= 0.0 ? kOutside : kInside;
            }
            light += lightThrough(headEntry, toHead, lights.headLight.rgb, eyeInside, medium);
#if DIRECTIONAL_LIGHTS
            for (uint i = 0u; i < lights.lightCount.x; ++i) {
                vec3 toLight = lights.lightDirection[i].xyz;
                Entry entry;
#if LIGHT_MAP_ENTRIES
                // The camera's and the light's reconstructions of one surface differ by a
                // fraction of the point spacing: a sample that close below the camera's surface
                // may lie that far in front of the light's (the shadows' tolerance). Deeper
                // samples need none, so that a thin part's far face cuts off exactly.
                float slack = max(lights.shadow.x - s * cosViewInside, 0.0);
                entry = lightMapEntry(i, samplePoint, slack, registration[i]);
                if (entry.state == kOffScreen) {
                    entry = localSlabEntry(s, toLight, normal, cosView);
                }
#else
                if (!local) {
                    // kExtinctionDepths of the least extinct channel along a straight path
                    // whose refracted length is shortened by cos θi/cos θi′ (at most 1/0.05).
                    float cosIn = max(dot(normal, toLight), 0.05);
                    float reach = kExtinctionDepths * refractedCosine(cosIn, eta) /
                                  (sigmaTMin * cosIn);
                    entry = marchToLight(samplePoint, sampleProbe, s, toLight, reach,
                                         thicknessScale);
                }
                if (local || entry.state == kOffScreen) {
                    entry = localSlabEntry(s, toLight, normal, cosView);
                }
#endif
                light += lightThrough(entry, toLight, lights.lightColor[i].rgb, eyeInside, medium);
            }
#endif
            single += medium.sigmaS * light * viewExtinction / density;
        }
        single *= fresnelTransmittance(cosView, eta) / (eta * eta);
    }
    if (exports) {
        imageStore(outSingle, pixel, vec4(single, 1.0));
    }
    imageStore(scatteredRadiance, pixel, vec4(base.rgb + single, base.a));
}
