#!/usr/bin/env bash
# Mutation check of the single-scattering tests: each deliberately wrong change to
# shaders/render/SingleScattering.comp, loaded through SUBSCAN_SHADER_DIR, must make
# SingleScatteringGLTest fail. Prints one line per mutation and exits non-zero when a mutation
# survives. Needs a built tree (build/tests/SingleScatteringGLTest).
set -euo pipefail
cd "$(dirname "$0")/.."
test_binary=build/tests/SingleScatteringGLTest
[[ -x "$test_binary" ]] || { echo "mutate: build $test_binary first" >&2; exit 1; }
shader=shaders/render/SingleScattering.comp
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# name | exact text | its wrong replacement
mutations=(
    "no beam compression|* cosIn / cosInInside * kPi;|* kPi;"
    "no 1/eta^2 on leaving|/ (eta * eta);|;"
    "phase of the wrong angle|henyeyGreenstein(-dot(lightInside, eyeInside)|henyeyGreenstein(dot(lightInside, eyeInside)"
    "unrefracted light path|float lightPath = entry.distance * cosIn / cosInInside;|float lightPath = entry.distance;"
    "no tangent-plane solve|clamp(crossing, inside, outside)|inside"
    "nearer objects stop the march|        return dot(last.normal, q - last.surfacePoint) < 0.0;|        return false;"
    "one channel's density only|dot(vec3(channelSamples) * medium.sigmaT, viewExtinction)|medium.sigmaT[channel] * viewExtinction[channel]"
    "no exit Fresnel|single *= fresnelTransmittance(cosView, eta)|single *= 1.0"
    "reduced sigma_s used unreduced|sigmaSPrime / (1.0 - g) * params.medium.z|sigmaSPrime * params.medium.z"
    "sigma_a from the difference|sigmaA = effectiveExtinction * root / sqrt(3.0);|sigmaA = effectiveExtinction / (sqrt(3.0) * root) - sigmaSPrime;"
)

survived=0
for mutation in "${mutations[@]}"; do
    IFS='|' read -r name from to <<<"$mutation"
    rm -rf "$work/shaders"
    cp -r shaders "$work/shaders"
    FROM="$from" TO="$to" perl -0pi -e 's/\Q$ENV{FROM}\E/$ENV{TO}/ or die "not found\n"' \
        "$work/shaders/render/SingleScattering.comp" ||
        { echo "mutate: '$name' no longer applies to $shader" >&2; exit 1; }
    if SUBSCAN_SHADER_DIR="$work/shaders" "$test_binary" >"$work/log" 2>&1; then
        echo "SURVIVED  $name"
        survived=1
    else
        echo "caught    $name ($(grep -c '^\[  FAILED  \] SingleScattering.*ms)' "$work/log") tests failed)"
    fi
done
exit "$survived"
