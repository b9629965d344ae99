#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "app/cli/CommandSupport.h"
#include "core/Camera.h"
#include "gpu/GlContext.h"
#include "io/ScanLoader.h"
#include "render/RenderSettings.h"

namespace subscan::cli {

/// What render and turntable share: the picture's size, camera, mode, stage and settings, the
/// GL context, and the guard against writing over the input.
struct FrameOptions {
    std::string source;  // the scan file, or synthetic:NAME
    int width = 1280;
    int height = 720;
    std::string mode;
    std::string stage;
    std::optional<float> pointSize;
    double yaw = 30.0;
    double pitch = 20.0;
    std::optional<double> distance;
    std::string up = "auto";
    SensorViewOptions sensorView;
    double fovy = 45.0;
    std::string cameraFile;
    std::string background;
    std::string raster;
    std::string resolution;
    ScatteringOptions scattering;
    std::string settingsFile;
    std::string saveSettingsFile;
    std::string color = "auto";  // Coloring
    bool verbose = false;
    bool software = false;
    StreamingOptions streaming;
    RenderMode defaultMode = RenderMode::Points;  // set by add()
    const CLI::App* parsedBy = nullptr;           // set by add(): which options were given

    /// The options on `command`; `modeByDefault` is the mode where neither --mode nor the
    /// settings file names one.
    void add(CLI::App& command, RenderMode modeByDefault = RenderMode::Points);
    /// The settings file's settings (over the defaults, where the file leaves a key out) with
    /// the given options written over them; throws subscan::Error naming a bad value or an
    /// option the view would ignore (--yaw with --view sensor, --sensor without it), and warns
    /// of those the mode ignores (--point-size outside splats, scattering outside sss).
    RenderSettings settings() const;
    /// The camera of --camera; or with --view sensor the sensor's (SensorViewOptions); or the
    /// orbit of --yaw, --pitch, --distance, --up and --fovy around the scan's bounds, framed by
    /// `framing` when --distance is not given.
    Camera camera(const LoadedScan& scan, Framing framing = Framing::Box) const;
    /// The up axis --up names for `scan` (auto: Z for LAS, else Y).
    UpAxis upAxis(const LoadedScan& scan) const;
    /// Replaces the scan's colours by what --color shows (core/Coloring.h); throws
    /// subscan::Error when the scan lacks what it needs.
    void applyColoring(LoadedScan& scan) const;
    /// A headless context (hardware unless --software), its renderer printed with --verbose.
    std::unique_ptr<GlContext> context() const;
    /// Throws subscan::Error when `output` is the input scan or the settings file: nothing is
    /// ever written over an input. `what` names the output ("the image", "the settings").
    void refuseToOverwriteInputs(const std::filesystem::path& output, std::string_view what) const;
    /// Whether `file` is one of the inputs: the scan, the settings file or the camera file.
    bool isInput(const std::filesystem::path& file) const;
    /// Writes --save-settings, if given (after the inputs are read).
    void saveSettings(const RenderSettings& settings) const;

  private:
    /// Whether the option `name` was given (not its default).
    bool given(const char* name) const;
    void checkIgnoredOptions(RenderMode effectiveMode) const;
    /// What kind of input `file` is ("scan", "settings file", "camera file"), or nullptr.
    const char* inputKindOf(const std::filesystem::path& file) const;
};

}  // namespace subscan::cli
