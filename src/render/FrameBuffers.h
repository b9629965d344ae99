#pragma once

#include <string>
#include <vector>

#include "io/Image.h"
#include "render/RenderSettings.h"
#include "render/Renderer.h"

namespace subscan {

/// One buffer of a frame: float values, rows top first.
struct FrameBuffer {
    std::string name;
    ImageF image;
};

/// The last frame's buffers, as `render --export-buffers` writes them and the Python module's
/// Renderer.buffers() returns them (one function, so that both give the same numbers):
///   "depth"    1 channel, the linear depth (reconstructed in the surface and sss modes), +inf
///              where nothing is;
///   "color"    3 channels, the linear colour of the points (the filled colour in the surface
///              and sss modes), 0 where depth is +inf;
/// and in the surface and sss modes
///   "normals"  3 channels, view-space unit normals;
///   "radiance" 3 channels, linear (after scattering in the sss mode);
///   "mask"     1 channel, 1 on the surface and 0 elsewhere;
/// and with single scattering "single", "sigma_s" and "sigma_a", 3 channels each (that term
/// alone in radiance's units; σs′ and σa in mm⁻¹). Sizes are renderer.pipelineCamera()'s.
/// Needs a frame rendered with FrameOutputs::Everything.
std::vector<FrameBuffer> readFrameBuffers(const Renderer& renderer, const RenderSettings& settings);

}  // namespace subscan
