#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "io/ScanLoader.h"
#include "render/ScatteringSettings.h"

namespace subscan::cli {

/// Loads a scan for a command: a progress bar on stderr for big files on a terminal, then the
/// reader's warnings printed as "subscan: warning: ...".
LoadedScan loadScanForCommand(std::string_view source);

/// Whether `a` and `b` are the same existing file, also through another spelling of the path or
/// a link: the guard that keeps commands from writing over their inputs.
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

/// "R,G,B": three numbers separated by commas (no spaces), or nullopt when `text` is not that.
std::optional<glm::vec3> parseCommaSeparatedRgb(const std::string& text);
/// "X,Y,Z" as three finite doubles (file coordinates keep their precision); nullopt otherwise.
std::optional<glm::dvec3> parseCommaSeparatedTriple(const std::string& text);

/// `--resolution full|half|auto` (RasterSettings::resolution), as render and bench take it.
void addResolutionOption(CLI::App& command, std::string& resolution);

/// The sss mode's options, as render, view and bench take them: each given one overrides the
/// settings file's value.
struct ScatteringOptions {
    std::string method;
    std::string material;
    std::string unit;
    std::optional<float> scale;
    std::string albedo;
    std::string coefficients;
    std::string meanFreePath;  // "R,G,B" in mm
    std::optional<float> eta;
    std::optional<float> phaseG;
    std::optional<int> singleSamples;
    std::string lightPath;

    void add(CLI::App& command);
    /// Writes the given options over `settings`; throws subscan::Error naming the option or the
    /// impossible combination (checkScatteringSettings).
    void apply(ScatteringSettings& settings) const;
};

}  // namespace subscan::cli
