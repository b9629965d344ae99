#pragma once

#include <filesystem>
#include <functional>

#include "app/cli/FrameOptions.h"
#include "core/Error.h"
#include "render/RenderSettings.h"
#include "render/Renderer.h"

namespace subscan::cli {

/// Whether `file` is named as a file exportBuffers may write: an earlier export's that the next
/// one does not write are removed by these names, and nothing else in the folder is.
bool isBufferFile(const std::filesystem::path& file);

/// The error for `entry` in a folder that --export-buffers would hold alone: it is no earlier
/// export's, and only those may be removed.
Error notAnExport(const std::filesystem::path& entry);

/// Throws subscan::Error where `directory` (if it exists) holds anything but buffer files and
/// what `alsoWritten` accepts (the command's other outputs), or where exportBuffers would write
/// over or remove an input (camera.json or buffers_camera.json being the --camera file).
void checkExportFolder(
    const FrameOptions& frame, const std::filesystem::path& directory,
    const std::function<bool(const std::filesystem::path&)>& alsoWritten = nullptr);

/// Removes an earlier export's `directory`: its buffer files, then the folder (which fails
/// where anything else has come into it since checkExportFolder).
void removeExport(const std::filesystem::path& directory);

/// camera.json, depth.pfm and color.png always; in the surface and sss modes also normals.pfm,
/// mask.png and radiance.pfm (after scattering in sss mode), with depth.pfm holding the
/// reconstructed depth (+inf outside the mask); with single scattering also single.pfm (that
/// term alone, linear RGB like radiance.pfm), sigma_s.pfm and sigma_a.pfm (σs′ and σa in mm⁻¹).
/// camera.json is `picture`, the camera the picture was rendered through, so `--camera` renders
/// it again. The buffers are the pipeline's last frame's: at reduced resolution smaller than the
/// picture, with the temporal filter at rest that frame's jittered camera (the picture being
/// the mean over many); where their camera is not the picture's it is written beside it as
/// buffers_camera.json. Buffer files of an earlier export in `directory` that this one does not
/// write are removed. Needs a frame rendered with FrameOutputs::Everything.
void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings, const Camera& picture);

}  // namespace subscan::cli
