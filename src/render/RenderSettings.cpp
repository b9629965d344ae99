#include "render/RenderSettings.h"

#include <array>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"

namespace subscan {

namespace {

constexpr std::array<std::pair<RenderMode, std::string_view>, 3> kModes{{
    {RenderMode::Points, "points"},
    {RenderMode::PointsGl, "points-gl"},
    {RenderMode::Splats, "splats"},
}};
constexpr std::array<std::pair<RasterPath, std::string_view>, 3> kPaths{{
    {RasterPath::Auto, "auto"},
    {RasterPath::Int64, "int64"},
    {RasterPath::TwoPass32, "two-pass"},
}};
constexpr std::array<std::pair<TimingMode, std::string_view>, 3> kTimings{{
    {TimingMode::Auto, "auto"},
    {TimingMode::GpuQueries, "gpu-queries"},
    {TimingMode::FinishAndClock, "finish-and-clock"},
}};

template <class Enum, std::size_t N>
std::string nameOf(const std::array<std::pair<Enum, std::string_view>, N>& table, Enum value) {
    for (const auto& [candidate, name] : table) {
        if (candidate == value) {
            return std::string(name);
        }
    }
    return "?";
}

template <class Enum, std::size_t N>
Enum parse(const std::array<std::pair<Enum, std::string_view>, N>& table, std::string_view text,
           std::string_view what) {
    std::string allowed;
    for (const auto& [value, name] : table) {
        if (name == text) {
            return value;
        }
        allowed += allowed.empty() ? "" : ", ";
        allowed += name;
    }
    throw Error(fmt::format("'{}' is not a {} (expected one of: {})", text, what, allowed));
}

}  // namespace

std::string toString(RenderMode mode) {
    return nameOf(kModes, mode);
}
RenderMode parseRenderMode(std::string_view text) {
    return parse(kModes, text, "render mode");
}
std::string toString(RasterPath path) {
    return nameOf(kPaths, path);
}
RasterPath parseRasterPath(std::string_view text) {
    return parse(kPaths, text, "raster path");
}

void to_json(nlohmann::json& json, const RasterSettings& settings) {
    json = {
        {"mode", toString(settings.mode)},
        {"raster_path", toString(settings.path)},
        {"point_size", settings.pointSize},
        {"background_srgb",
         {settings.backgroundSrgb.r, settings.backgroundSrgb.g, settings.backgroundSrgb.b}},
        {"timing", nameOf(kTimings, settings.timing)},
    };
}

void from_json(const nlohmann::json& json, RasterSettings& settings) {
    // Absent keys keep their defaults, so a settings file may hold only what it changes.
    if (json.contains("mode")) {
        settings.mode = parseRenderMode(json.at("mode").get<std::string>());
    }
    if (json.contains("raster_path")) {
        settings.path = parseRasterPath(json.at("raster_path").get<std::string>());
    }
    if (json.contains("point_size")) {
        settings.pointSize = json.at("point_size").get<float>();
        if (!(settings.pointSize >= 1.0f && settings.pointSize <= 64.0f)) {
            throw Error(fmt::format("point_size {} is outside 1..64 pixels", settings.pointSize));
        }
    }
    if (json.contains("background_srgb")) {
        const auto values = json.at("background_srgb").get<std::array<float, 3>>();
        for (const float value : values) {
            if (!(value >= 0.0f && value <= 1.0f)) {
                throw Error("background_srgb values must lie in 0..1");
            }
        }
        settings.backgroundSrgb = {values[0], values[1], values[2]};
    }
    if (json.contains("timing")) {
        settings.timing = parse(kTimings, json.at("timing").get<std::string>(), "timing mode");
    }
}

}  // namespace subscan
