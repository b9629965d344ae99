#pragma once

#include <filesystem>

#include <nlohmann/json_fwd.hpp>

#include "core/Camera.h"

namespace subscan {

/// camera.json (DESIGN.md §4): width, height, fovy_deg, near, far, `view` (file coordinates ->
/// view space) and `projection` (view -> clip), both as 4 rows of 4 numbers (row-major); a
/// camera the temporal filter shifted also has `jitter_pixels` [x, y] (Camera::jitterPixels,
/// in `projection` too), and a sensor's camera `principal_offset_pixels` [x, y]
/// (Camera::principalOffsetPixels), each absent when zero.
nlohmann::json cameraToJson(const Camera& camera);
/// Validates every field. `projection` follows from fovy, near, far, the image size and the
/// pixel offsets: where given it must agree with them. `view` must be a rigid motion. Throws
/// subscan::Error naming the field.
Camera cameraFromJson(const nlohmann::json& json);

void writeCameraFile(const std::filesystem::path& path, const Camera& camera);
Camera readCameraFile(const std::filesystem::path& path);

}  // namespace subscan
