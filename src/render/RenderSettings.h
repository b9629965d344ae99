#pragma once

#include <filesystem>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "gpu/PassTimer.h"

namespace subscan {

/// What the frame pipeline draws.
enum class RenderMode {
    Points,    // compute-rasterized 1-pixel points (the input of the reconstruction)
    PointsGl,  // baseline: GL_POINTS, 1 pixel
    Splats,    // baseline: GL_POINTS of pointSize pixels with depth test (common viewers)
};

/// Which compute rasterizer runs: Auto takes the one-pass 64-bit path where the driver has
/// 64-bit atomics and the two-pass 32-bit path elsewhere; the others force one (tests, bench).
enum class RasterPath { Auto, Int64, TwoPass32 };

/// Settings of the rasterization and presentation (one struct per concern; JSON load/save).
struct RasterSettings {
    RenderMode mode = RenderMode::Points;
    RasterPath path = RasterPath::Auto;
    float pointSize = 4.0f;                         // splats, in pixels
    glm::vec3 backgroundSrgb{0.19f, 0.19f, 0.19f};  // sRGB-encoded 0..1, like colour pickers
    TimingMode timing = TimingMode::Auto;
};

void to_json(nlohmann::json& json, const RasterSettings& settings);
void from_json(const nlohmann::json& json, RasterSettings& settings);

std::string toString(RenderMode mode);
/// Throws subscan::Error naming the allowed values.
RenderMode parseRenderMode(std::string_view text);
std::string toString(RasterPath path);
RasterPath parseRasterPath(std::string_view text);

}  // namespace subscan
