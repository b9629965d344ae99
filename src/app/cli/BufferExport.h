#pragma once

#include <filesystem>

#include "app/cli/FrameOptions.h"
#include "render/RenderSettings.h"
#include "render/Renderer.h"

namespace subscan::cli {

/// camera.json, depth.pfm and color.png always; in the surface and sss modes also normals.pfm,
/// mask.png and radiance.pfm (after scattering in sss mode), with depth.pfm holding the
/// reconstructed depth (+inf outside the mask); with single scattering also single.pfm (that
/// term alone, linear RGB like radiance.pfm), sigma_s.pfm and sigma_a.pfm (σs′ and σa in mm⁻¹).
/// camera.json is `picture`, the camera the picture was rendered through, so `--camera` renders
/// it again. The buffers are the pipeline's last frame's: at reduced resolution smaller than the
/// picture, with the temporal filter at rest that frame's jittered camera (the picture being
/// the mean over many); where their camera is not the picture's it is written beside it as
/// buffers_camera.json. Needs a frame rendered with FrameOutputs::Everything.
/// Throws subscan::Error where exportBuffers into `directory` would write over (or remove) an
/// input: its camera.json or buffers_camera.json being the --camera file.
void refuseToOverwriteCameraInputs(const FrameOptions& frame,
                                   const std::filesystem::path& directory);

void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings, const Camera& picture);

}  // namespace subscan::cli
