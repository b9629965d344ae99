// Binding indices and GPU struct layouts, included by both C++ (src/) and GLSL (shaders/):
// each number and each layout exists exactly once. Structs use only 16-byte members (vec4,
// uvec4, mat4) or scalars in groups of four, so std140 and C++ agree; C++ static_asserts check
// the sizes.
#ifndef SUBSCAN_BINDINGS_H
#define SUBSCAN_BINDINGS_H

#ifdef __cplusplus
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
namespace subscan::gpu {
using uint = std::uint32_t;
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using mat4 = glm::mat4;
#endif

// ---- uniform blocks (std140) ----
#define SUBSCAN_UBO_FRAME 0
#define SUBSCAN_UBO_PASS 1

// ---- shader storage blocks (std430) ----
#define SUBSCAN_SSBO_POSITIONS 0    // float x, y, z per point (cloud-relative)
#define SUBSCAN_SSBO_COLORS 1       // uint RGBA8, sRGB-encoded, per point
#define SUBSCAN_SSBO_DEPTH_BITS 2   // uint per pixel: floatBitsToUint(linear depth)
#define SUBSCAN_SSBO_POINT_INDEX 3  // uint per pixel: the winning point
#define SUBSCAN_SSBO_DEPTH_INDEX 4  // uint64 per pixel: depth bits << 32 | point index

// ---- images ----
#define SUBSCAN_IMAGE_OUT0 0
#define SUBSCAN_IMAGE_OUT1 1
#define SUBSCAN_IMAGE_IN0 2
#define SUBSCAN_IMAGE_IN1 3

// ---- vertex attributes (GL_POINTS baseline) ----
#define SUBSCAN_ATTRIBUTE_POSITION 0
#define SUBSCAN_ATTRIBUTE_COLOR 1

// ---- compute work group sizes ----
#define SUBSCAN_POINTS_GROUP_SIZE 256
#define SUBSCAN_IMAGE_GROUP_SIZE 8

// Per-frame camera and viewport. Images have row 0 at the top, like the PNG output.
struct FrameParams {
    mat4 viewFromCloud;  // cloud-relative positions -> view space (built in double on the CPU)
    mat4 projection;     // view -> clip, OpenGL convention
    vec4 viewport;       // width, height, 1 / width, 1 / height
    vec4 depthRange;     // near, far, focal length in pixels, unused
    vec4 background;     // linear RGB, alpha unused
};

// RasterizePoints: which slice of the cloud this dispatch covers.
struct RasterParams {
    uint firstPoint;  // global index of the chunk's first point
    uint pointCount;  // points in this chunk
    uint pixelCount;  // width * height
    uint unused0;
};

// DrawPoints (GL_POINTS baselines).
struct DrawParams {
    vec4 pointSize;  // x: size in pixels
};

#ifdef __cplusplus
static_assert(sizeof(FrameParams) == 2 * 64 + 3 * 16);
static_assert(sizeof(RasterParams) == 16);
static_assert(sizeof(DrawParams) == 16);
}  // namespace subscan::gpu
#endif

#endif
