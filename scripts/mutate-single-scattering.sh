#!/usr/bin/env bash
# Mutation check of the single-scattering tests: each deliberately wrong change to
# shaders/render/SingleScattering.comp, loaded through SUBSCAN_SHADER_DIR, must make
# SingleScatteringGLTest fail. Prints one line per mutation and exits non-zero when a mutation
# survives. Needs a built tree (build/tests/SingleScatteringGLTest).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mutation-check.sh
pass=render/SingleScattering.comp

# name | shader | exact text | its wrong replacement
check_mutations build/tests/SingleScatteringGLTest \
    "no beam compression|$pass|* cosIn / cosInInside * kPi;|* kPi;" \
    "no 1/eta^2 on leaving|$pass|/ (eta * eta);|;" \
    "phase of the wrong angle|$pass|henyeyGreenstein(-dot(lightInside, eyeInside)|henyeyGreenstein(dot(lightInside, eyeInside)" \
    "unrefracted light path|$pass|float lightPath = entry.distance * cosIn / cosInInside;|float lightPath = entry.distance;" \
    "no tangent-plane solve|$pass|clamp(crossing, inside, outside)|inside" \
    "nearer objects stop the march|$pass|        return dot(last.normal, q - last.surfacePoint) < 0.0;|        return false;" \
    "one channel's density only|$pass|dot(vec3(channelSamples) * medium.sigmaT, viewExtinction)|medium.sigmaT[channel] * viewExtinction[channel]" \
    "no exit Fresnel|$pass|single *= fresnelTransmittance(cosView, eta)|single *= 1.0" \
    "reduced sigma_s used unreduced|$pass|sigmaSPrime / (1.0 - g) * params.medium.z|sigmaSPrime * params.medium.z" \
    "sigma_a from the difference|$pass|sigmaA = effectiveExtinction * root / sqrt(3.0);|sigmaA = effectiveExtinction / (sqrt(3.0) * root) - sigmaSPrime;"
