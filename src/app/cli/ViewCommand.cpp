#include <cerrno>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include <fmt/format.h>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "app/viewer/Viewer.h"
#include "app/viewer/ViewerScript.h"
#include "core/Coloring.h"
#include "core/Error.h"
#include "render/RenderSettings.h"

namespace subscan::cli {

namespace {

struct ViewCommandOptions {
    std::string source;
    int width = 1280;
    int height = 800;
    std::string mode;
    ScatteringOptions scattering;
    std::string settingsFile;
    std::string up = "auto";
    std::string color = "auto";
    std::string scriptFile;
    std::string screenshot;
    std::optional<int> exitAfterFrames;
    bool hidePanel = false;
};

/// Everything that can be wrong with the input is found before a window opens, so that a bad
/// file reads the same with and without a display.
viewer::ViewerOptions checkedOptions(const ViewCommandOptions& command) {
    viewer::ViewerOptions options;
    options.source = command.source;
    options.width = command.width;
    options.height = command.height;
    options.showPanel = !command.hidePanel;
    options.exitAfterFrames = command.exitAfterFrames;
    options.screenshotAtExit = command.screenshot;
    if (command.up != "auto") {
        options.up = upAxisFor(command.up, "");
    }
    options.coloring = parseColoring(command.color);
    if (!command.settingsFile.empty()) {
        options.settings = readSettingsFile(command.settingsFile, viewer::viewerDefaultSettings());
    }
    if (!command.mode.empty()) {
        options.settings.raster.mode = parseRenderMode(command.mode);
    }
    command.scattering.apply(options.settings.scattering);
    if (!command.scriptFile.empty()) {
        options.script = viewer::readScriptFile(command.scriptFile);
    }

    const bool synthetic = command.source.starts_with("synthetic:");
    if (!synthetic) {
        std::error_code error;
        if (!std::filesystem::exists(command.source, error)) {
            throw Error(
                fmt::format("{}: cannot open the file: {}", command.source, std::strerror(ENOENT)));
        }
        auto refuseOverwrite = [&](const std::filesystem::path& output) {
            if (sameFile(output, command.source)) {
                throw Error(fmt::format("{}: refusing to write a screenshot over the input scan",
                                        output.string()));
            }
        };
        refuseOverwrite(options.screenshotAtExit);
        for (const viewer::ScriptAction& action : options.script) {
            if (const auto* screenshot = std::get_if<viewer::script::Screenshot>(&action.command)) {
                refuseOverwrite(screenshot->path);
            }
        }
    }
    return options;
}

}  // namespace

Command addViewCommand(CLI::App& parent) {
    auto options = std::make_shared<ViewCommandOptions>();
    CLI::App* view =
        parent.add_subcommand("view", "Interactive viewer (a window with OpenGL 4.5 and a panel)");
    view->add_option("scan", options->source, "Scan file, or synthetic:NAME")->required();
    view->add_option("--width", options->width, "Window width in pixels")
        ->check(CLI::Range(64, 16384));
    view->add_option("--height", options->height, "Window height in pixels")
        ->check(CLI::Range(64, 16384));
    view->add_option("--mode", options->mode,
                     "points (default) | points-gl | splats | surface | sss")
        ->check(CLI::IsMember({"points", "points-gl", "splats", "surface", "sss"}));
    options->scattering.add(*view);
    view->add_option("--settings", options->settingsFile,
                     "Settings JSON, as `subscan render --settings` reads; --mode and "
                     "the scattering options override it")
        ->check(CLI::ExistingFile);
    view->add_option("--up", options->up, kUpAxisHelp)->check(CLI::IsMember(kUpAxisNames));
    view->add_option("--color", options->color,
                     "What the points' colour shows: auto | rgb | intensity | height | uniform | "
                     "classification")
        ->check(CLI::IsMember(coloringNames()));
    view->add_option("--script", options->scriptFile,
                     "JSON list of timed camera actions (docs/cli.md#subscan-view)")
        ->check(CLI::ExistingFile);
    view->add_option("--screenshot", options->screenshot,
                     "PNG of the window (panel included) to write at exit, with its .camera.json "
                     "and .settings.json");
    view->add_option("--exit-after-frames", options->exitAfterFrames,
                     "Quit after this many frames showing the scan")
        ->check(CLI::PositiveNumber);
    view->add_flag("--hide-panel", options->hidePanel, "Start with the panel hidden (Tab)");
    return {view, [options] {
                viewer::Viewer viewer(checkedOptions(*options));
                return viewer.run();
            }};
}

}  // namespace subscan::cli
