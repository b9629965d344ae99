#version 450
#include "shared/common.glsl"

in vec3 linearColor;
in float linearDepth;

layout(location = 0) out vec4 outColor;
layout(location = 1) out float outDepth;

void main() {
    outColor = vec4(linearColor, 1.0);
    outDepth = linearDepth;
}
