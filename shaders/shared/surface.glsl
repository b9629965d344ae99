// The reconstruction passes' parameters (SurfaceParams), for the passes and the includes that
// turn their radii into pyramid levels.
#include "shared/common.glsl"

layout(std140, binding = SUBSCAN_UBO_SURFACE) uniform SurfaceBlock {
    SurfaceParams surface;
};
