#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json_fwd.hpp>

#include "core/Coloring.h"
#include "render/RenderSettings.h"

namespace subscan::viewer {

/// Scripted input for unattended runs (tests, demos, recordings): what a user would do with the
/// mouse and keys, at given frames. Pixels are window pixels from the top left; `at` defaults to
/// the middle of the window.
namespace script {

struct Orbit {  // a left drag
    double dx = 0.0;
    double dy = 0.0;
};
struct Pan {  // a right or middle drag
    double dx = 0.0;
    double dy = 0.0;
};
struct Zoom {  // wheel steps at the cursor; positive comes closer
    double amount = 0.0;
    std::optional<glm::dvec2> at;
};
struct Pick {  // a double click: orbit around the surface under the cursor
    std::optional<glm::dvec2> at;
};
struct Reset {};     // `R`
struct FrameAll {};  // `F`
struct Sensor {};    // `V`: the view from the scan's sensor
struct Color {       // the panel's "colour" choice
    Coloring coloring = Coloring::Auto;
};
struct Resize {
    int width = 0;
    int height = 0;
};
struct Screenshot {  // `P`, to a chosen path
    std::filesystem::path path;
};
struct SetMode {
    RenderMode mode = RenderMode::Points;
};
struct ShowPanel {  // `Tab`
    bool show = true;
};
/// A left drag with `L` held: turns the first directional light (ViewerCamera::dragLight),
/// adding one first when there is none, as pressing `L` does.
struct Light {
    double dx = 0.0;
    double dy = 0.0;
};
/// What the panel does: settings in the settings file's form merged into the current ones (a
/// JSON merge patch, RFC 7386), e.g. {"scattering": {"method": "single"}}.
struct Settings {
    std::string patch;  // JSON text of an object
};
struct Exit {};

}  // namespace script

using ScriptCommand =
    std::variant<script::Orbit, script::Pan, script::Zoom, script::Pick, script::Reset,
                 script::FrameAll, script::Sensor, script::Color, script::Resize,
                 script::Screenshot, script::SetMode, script::ShowPanel, script::Light,
                 script::Settings, script::Exit>;

struct ScriptAction {
    /// Frames count from the first frame that shows the scan (0); the actions of a frame run
    /// before it is drawn, in the order of the file.
    int frame = 0;
    ScriptCommand command;
};

/// The script as JSON: a list of {"frame": N, "action": NAME, ...arguments}. Returns the actions
/// ordered by frame (stable). Throws subscan::Error naming the action (by position from 1) and
/// what is wrong with it; unknown keys are errors, so a misspelt argument is not ignored.
std::vector<ScriptAction> parseScript(const nlohmann::json& json);
/// parseScript of a file; errors name the file.
std::vector<ScriptAction> readScriptFile(const std::filesystem::path& path);

}  // namespace subscan::viewer
