#version 450
// Sets every word of a storage buffer, or every texel of an image, to one value: the driver's
// clear done as the GPU's own work (gpu/GpuClear.h says where and why).
//   CLEAR_BUFFER  the words bound at SUBSCAN_SSBO_CLEAR, a grid-stride loop (few work groups
//                 however large the buffer)
//   CLEAR_UINT    the r32ui image at SUBSCAN_IMAGE_OUT0
//   otherwise     the float image at SUBSCAN_IMAGE_OUT0, of format IMAGE_FORMAT
// An image's texels [origin, origin + size) only.
#include "shared/bindings.h"

#if CLEAR_BUFFER
layout(local_size_x = SUBSCAN_CLEAR_GROUP_SIZE) in;
layout(std430, binding = SUBSCAN_SSBO_CLEAR) writeonly buffer Words {
    uint words[];
};
layout(location = 0) uniform uint value;
layout(location = 1) uniform uint wordCount;

void main() {
    uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
    for (uint i = gl_GlobalInvocationID.x; i < wordCount; i += stride) {
        words[i] = value;
    }
}
#else
layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = SUBSCAN_IMAGE_GROUP_SIZE) in;
#if CLEAR_UINT
layout(binding = SUBSCAN_IMAGE_OUT0, r32ui) writeonly uniform uimage2D target;
layout(location = 0) uniform uvec4 value;
#else
layout(binding = SUBSCAN_IMAGE_OUT0, IMAGE_FORMAT) writeonly uniform image2D target;
layout(location = 0) uniform vec4 value;
#endif
layout(location = 1) uniform ivec2 origin;
layout(location = 2) uniform ivec2 size;

void main() {
    ivec2 offset = ivec2(gl_GlobalInvocationID.xy);
    if (all(lessThan(offset, size))) {
        imageStore(target, origin + offset, value);
    }
}
#endif
