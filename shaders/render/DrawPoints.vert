#version 450
// GL_POINTS baselines: what plain point viewers draw (1 px, or square splats of K px).
#include "shared/common.glsl"

layout(std140, binding = SUBSCAN_UBO_PASS) uniform DrawBlock {
    DrawParams draw;
};
layout(location = SUBSCAN_ATTRIBUTE_POSITION) in vec3 position;
layout(location = SUBSCAN_ATTRIBUTE_COLOR) in vec4 color;  // unorm, sRGB-encoded

out vec3 linearColor;
out float linearDepth;

void main() {
    vec4 viewPosition = frame.viewFromCloud * vec4(position, 1.0);
    gl_Position = frame.projection * viewPosition;
    // Images keep row 0 at the top (like the PNG); GL's window origin is the bottom.
    gl_Position.y = -gl_Position.y;
    gl_PointSize = draw.pointSize.x;
    linearColor = srgbToLinear(color.rgb);
    linearDepth = -viewPosition.z;
}
