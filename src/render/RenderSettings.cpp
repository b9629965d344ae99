#include "render/RenderSettings.h"

#include <array>
#include <fstream>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/JsonText.h"
#include "render/SettingsJson.h"
#include "shared/bindings.h"

namespace subscan {

namespace {

constexpr std::pair<RenderMode, std::string_view> kModes[] = {
    {RenderMode::Points, "points"}, {RenderMode::PointsGl, "points-gl"},
    {RenderMode::Splats, "splats"}, {RenderMode::Surface, "surface"},
    {RenderMode::Sss, "sss"},
};
constexpr std::pair<RasterPath, std::string_view> kPaths[] = {
    {RasterPath::Auto, "auto"},
    {RasterPath::Int64, "int64"},
    {RasterPath::TwoPass32, "two-pass"},
};
constexpr std::pair<ClearPath, std::string_view> kClearPaths[] = {
    {ClearPath::Auto, "auto"},
    {ClearPath::Driver, "driver"},
    {ClearPath::Compute, "compute"},
};
constexpr std::pair<TimingMode, std::string_view> kTimings[] = {
    {TimingMode::Auto, "auto"},
    {TimingMode::GpuQueries, "gpu-queries"},
    {TimingMode::FinishAndClock, "finish-and-clock"},
};
constexpr std::pair<Stage, std::string_view> kStages[] = {
    {Stage::Final, "final"},     {Stage::Depth, "depth"},
    {Stage::Pyramid, "pyramid"}, {Stage::Visibility, "visibility"},
    {Stage::Pull, "pull"},       {Stage::Push, "push"},
    {Stage::Fill, "fill"},       {Stage::Normals, "normals"},
    {Stage::Shaded, "shaded"},
};
constexpr std::pair<Resolution, std::string_view> kResolutions[] = {
    {Resolution::Full, "full"},
    {Resolution::Half, "half"},
    {Resolution::Auto, "auto"},
};

}  // namespace

std::string toString(RenderMode mode) {
    return nameOf(kModes, mode);
}
RenderMode parseRenderMode(std::string_view text) {
    return parseName(kModes, text, "render mode");
}
std::string toString(RasterPath path) {
    return nameOf(kPaths, path);
}
RasterPath parseRasterPath(std::string_view text) {
    return parseName(kPaths, text, "raster path");
}
std::string toString(Stage stage) {
    return nameOf(kStages, stage);
}
Stage parseStage(std::string_view text) {
    return parseName(kStages, text, "stage");
}
std::string toString(Resolution resolution) {
    return nameOf(kResolutions, resolution);
}
Resolution parseResolution(std::string_view text) {
    return parseName(kResolutions, text, "resolution");
}

bool reconstructsSurface(RenderMode mode) {
    return mode == RenderMode::Surface || mode == RenderMode::Sss;
}
bool isFinalImage(Stage stage) {
    return stage == Stage::Final || stage == Stage::Shaded;
}

bool placesOutlineBySubpixels(const RenderSettings& settings) {
    return settings.surface.subpixelOutline && reconstructsSurface(settings.raster.mode);
}

bool usesPointNormals(const RenderSettings& settings) {
    return settings.surface.normals == NormalSource::Points &&
           reconstructsSurface(settings.raster.mode);
}

bool followsNormalsToOutline(const RenderSettings& settings) {
    return settings.surface.outlineNormals && reconstructsSurface(settings.raster.mode) &&
           !usesPointNormals(settings);
}

bool filtersTemporally(const RenderSettings& settings) {
    return settings.temporal.enabled && reconstructsSurface(settings.raster.mode) &&
           settings.raster.stage == Stage::Final;
}

void to_json(nlohmann::json& json, const RasterSettings& settings) {
    json = {
        {"mode", toString(settings.mode)},
        {"raster_path", toString(settings.path)},
        {"point_size", settings.pointSize},
        {"background_srgb", toJson(settings.backgroundSrgb)},
        {"timing", nameOf(kTimings, settings.timing)},
        {"clears", nameOf(kClearPaths, settings.clears)},
        {"stage", toString(settings.stage)},
        {"stage_level", settings.stageLevel},
        {"resolution", toString(settings.resolution)},
        {"color_blend", settings.colorBlend},
        {"normal_blend", settings.normalBlend},
    };
}

void from_json(const nlohmann::json& json, RasterSettings& settings) {
    rejectUnknownKeys(json, "raster",
                      {"mode", "raster_path", "point_size", "background_srgb", "timing", "clears",
                       "stage", "stage_level", "resolution", "color_blend", "normal_blend"});
    readEnum(json, "mode", settings.mode, kModes, "render mode");
    readEnum(json, "raster_path", settings.path, kPaths, "raster path");
    readSetting(json, "point_size", settings.pointSize, 1.0f, 64.0f);
    readSetting(json, "background_srgb", settings.backgroundSrgb, 0.0f, 1.0f);
    readEnum(json, "timing", settings.timing, kTimings, "timing mode");
    readEnum(json, "clears", settings.clears, kClearPaths, "clear path");
    readEnum(json, "stage", settings.stage, kStages, "stage");
    readSetting(json, "stage_level", settings.stageLevel, 0, SUBSCAN_MAX_PYRAMID_LEVELS - 1);
    readEnum(json, "resolution", settings.resolution, kResolutions, "resolution");
    readSetting(json, "color_blend", settings.colorBlend, 0.0f, 1.0f);
    readSetting(json, "normal_blend", settings.normalBlend, 0.0f, 16.0f);
}

void to_json(nlohmann::json& json, const TemporalSettings& settings) {
    json = {
        {"enabled", settings.enabled},
        {"new_frame_weight", settings.newFrameWeight},
        {"clip_sigma", settings.clipSigma},
        {"max_frames", settings.maxFrames},
    };
}

void from_json(const nlohmann::json& json, TemporalSettings& settings) {
    rejectUnknownKeys(json, "temporal",
                      {"enabled", "new_frame_weight", "clip_sigma", "max_frames"});
    readSetting(json, "enabled", settings.enabled);
    readSetting(json, "new_frame_weight", settings.newFrameWeight, 0.01f, 1.0f);
    readSetting(json, "clip_sigma", settings.clipSigma, 0.1f, 100.0f);
    // More frames change nothing a picture shows: 1/2048 of a colour step.
    readSetting(json, "max_frames", settings.maxFrames, 1, 2048);
}

void to_json(nlohmann::json& json, const StreamingSettings& settings) {
    json = {
        {"lod", nameOf(lod::kLodModeNames, settings.lod)},
        {"point_budget", settings.pointBudget},
        {"node_cache_megabytes", settings.nodeCacheMegabytes},
        {"upload_megabytes_per_frame", settings.uploadMegabytesPerFrame},
    };
}

void from_json(const nlohmann::json& json, StreamingSettings& settings) {
    rejectUnknownKeys(
        json, "streaming",
        {"lod", "point_budget", "node_cache_megabytes", "upload_megabytes_per_frame"});
    readEnum(json, "lod", settings.lod, lod::kLodModeNames, "level-of-detail mode");
    // 2^40 points: more than any survey a machine of today holds.
    readSetting(json, "point_budget", settings.pointBudget, std::uint64_t{0},
                std::uint64_t{1} << 40);
    // 16 MiB holds a view of a few hundred thousand points; 2^20 MiB (1 TiB), more than any
    // machine's memory.
    readSetting(json, "node_cache_megabytes", settings.nodeCacheMegabytes, std::uint64_t{16},
                std::uint64_t{1} << 20);
    // At least a MiB: an upload must go on. 2^20 MiB (1 TiB): every view in one frame.
    readSetting(json, "upload_megabytes_per_frame", settings.uploadMegabytesPerFrame,
                std::uint64_t{1}, std::uint64_t{1} << 20);
}

void to_json(nlohmann::json& json, const RenderSettings& settings) {
    json = {
        {"raster", settings.raster},     {"surface", settings.surface},
        {"shading", settings.shading},   {"scattering", settings.scattering},
        {"temporal", settings.temporal}, {"streaming", settings.streaming},
    };
}

void from_json(const nlohmann::json& json, RenderSettings& settings) {
    if (!json.is_object()) {
        throw Error("the settings must be a JSON object");
    }
    for (const auto& [key, value] : json.items()) {
        if (key != "raster" && key != "surface" && key != "shading" && key != "scattering" &&
            key != "temporal" && key != "streaming") {
            throw Error(
                fmt::format("unknown settings section '{}' (expected raster, surface, "
                            "shading, scattering, temporal, streaming)",
                            key));
        }
    }
    // Each section's absent keys keep what `settings` holds.
    json.value("raster", nlohmann::json::object()).get_to(settings.raster);
    json.value("surface", nlohmann::json::object()).get_to(settings.surface);
    json.value("shading", nlohmann::json::object()).get_to(settings.shading);
    json.value("scattering", nlohmann::json::object()).get_to(settings.scattering);
    json.value("temporal", nlohmann::json::object()).get_to(settings.temporal);
    json.value("streaming", nlohmann::json::object()).get_to(settings.streaming);
}

RenderSettings readSettingsFile(const std::filesystem::path& path, const RenderSettings& defaults) {
    std::ifstream stream(path);
    if (!stream) {
        throw Error(fmt::format("{}: cannot open the settings file", path.string()));
    }
    try {
        RenderSettings settings = defaults;
        parseJsonText(stream).get_to(settings);
        return settings;
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", path.string(), error.what()));
    }
}

void writeSettingsFile(const std::filesystem::path& path, const RenderSettings& settings) {
    writeFileAtomically(path, nlohmann::json(settings).dump(2) + "\n");
}

}  // namespace subscan
