#!/usr/bin/env bash
# Mutation check of the references that once were blind (issue 24): each deliberately wrong
# change must make a test that compares with an independent reference or ground truth fail.
#   - Blinn-Phong's halfway vector replaced by the view vector (ShadeGLTest: directional lights
#     against the CPU formula);
#   - the surface's depth pulled 2 h towards the camera in both paths, fused and per pass
#     (EvaluationGLTest: the sculpture's depth bias against the analytic truth);
#   - a GL error left in a pass that harness tests run directly, not through PassRunner
#     (SurfacePassesGLTest: every GL test fails on a GL error raised during it);
#   - the directional lights turned into view space by the wrong matrix (ShadeGLTest);
#   - the profile's widest, or its middle, Gaussian left out of the blur
#     (SubsurfaceScatteringGLTest: one lit pixel against the profile, within 3 % of each value).
# Shader changes load through SUBSCAN_SHADER_DIR; source changes rebuild one test in build/ and
# are put back afterwards. Needs a built tree (scripts/test.sh, or cmake --build build).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mutation-check.sh
status=0

check_mutations build/tests/ShadeGLTest \
    "halfway vector is the view vector|render/Shade.glsl|vec3 halfway = normalize(direction + toEye);|vec3 halfway = toEye;" ||
    status=1
check_mutations build/tests/EvaluationGLTest \
    "surface 2 h towards the camera|render/FinishSurface.comp|        depth = filled.x;|        depth = filled.x - 2.0 * surface.fill.x;|render/FillRemoval.comp|vec4(surfacePixel ? depth : kInfinity)|vec4(surfacePixel ? depth - 2.0 * surface.fill.x : kInfinity)" ||
    status=1
check_source_mutations SurfacePassesGLTest \
    "a GL error left in the shading pass|src/render/ShadePass.cpp|    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT|    glBindImageTexture(1u << 20, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F); glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT" ||
    status=1
check_source_mutations ShadeGLTest \
    "lights turned by the transposed view|src/render/ShadePass.cpp|            camera.view * glm::dvec4(towardsLightInWorld|            glm::transpose(camera.view) * glm::dvec4(towardsLightInWorld" ||
    status=1
check_source_mutations SubsurfaceScatteringGLTest \
    "the widest Gaussian left out|src/render/SubsurfaceScatteringPass.cpp|    for (const Gaussian& term : terms) {|    terms.pop_back(); for (const Gaussian& term : terms) {" \
    "the middle Gaussian left out|src/render/SubsurfaceScatteringPass.cpp|    for (const Gaussian& term : terms) {|    terms.erase(terms.begin() + terms.size() / 2); for (const Gaussian& term : terms) {" ||
    status=1
exit "$status"
