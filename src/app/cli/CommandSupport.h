#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/vec3.hpp>

#include "io/PointRecordSource.h"
#include "io/ScanLoader.h"
#include "lod/NodeSource.h"
#include "render/RenderSettings.h"
#include "render/ScatteringSettings.h"

namespace subscan::cli {

/// --up's choices and help, as render, view, turntable and bench take it (upAxisForScan).
inline const std::vector<std::string> kUpAxisNames{"auto", "y", "z", "-y"};
inline constexpr const char* kUpAxisHelp =
    "Up axis: auto (z for LAS, -y for a depth camera's organised grid in its own frame, else y) "
    "| y | z | -y";

/// A check for every floating-point option: CLI11 reads "nan", "inf" and "1e999" as numbers,
/// and its range checks let NaN through (every comparison with it is false), which gave an
/// empty picture and exit 0.
CLI::Validator finiteNumber();

/// A check that refuses a value `parse` throws subscan::Error for, with the error's sentence:
/// a bad value is then a usage error that CLI11 names the option in (`--material: ...`).
CLI::Validator parsedBy(std::function<void(const std::string&)> parse);

/// Throws subscan::Error when the folder `output` (a file to write) would go into does not
/// exist: said before the work, not after it, with other outputs already written.
void requireOutputFolder(const std::filesystem::path& output);

/// Removes `path`, a file or an empty folder an earlier run wrote (`what` names it: "this frame of
/// an earlier turntable"); throws subscan::Error saying why it cannot. One that does not exist
/// is no error.
void removeEarlierOutput(const std::filesystem::path& path, std::string_view what);

/// Loads a scan for a command: a progress bar on stderr for big files on a terminal, then the
/// reader's warnings printed as "subscan: warning: ...". `keepFilePrecision` as loadScan's
/// (commands that write the points as files).
LoadedScan loadScanForCommand(std::string_view source, bool keepFilePrecision = false);

/// A record source's warnings (io/PointRecordSource.h) as "subscan: warning: ..." lines, as
/// loadScanForCommand prints a reader's.
void printSourceWarnings(const PointRecordSourceInfo& info);

/// --lod and --point-budget, as render, turntable and bench take them.
struct StreamingOptions {
    std::optional<std::string> lod;            // unset: the settings' (streaming.lod)
    std::optional<std::uint64_t> pointBudget;  // unset: the settings' (streaming.point_budget)

    void add(CLI::App& command);
    /// The options given, written over `settings`; throws subscan::Error for a bad mode.
    void apply(StreamingSettings& settings) const;
};

/// The nodes `cameras` show within `pointBudget` (lod::selectNodes), loaded on every core, with
/// the whole survey's bounds (so that colouring by height does not depend on the budget).
/// Prints a warning for each node left out.
LoadedScan loadStreamedView(const lod::NodeSource& source, std::span<const Camera> cameras,
                            std::uint64_t pointBudget);

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
    std::vector<const CLI::Option*> added;  // by add(): which of them were given

    void add(CLI::App& command);
    /// Writes the given options over `settings`; throws subscan::Error naming the impossible
    /// combination (checkScatteringSettings). A bad value of one option is a usage error,
    /// refused while the command line is parsed, with the option's name.
    void apply(ScatteringSettings& settings) const;
};

/// --view orbit|sensor and --sensor X,Y,Z, as render, turntable and bench take them.
struct SensorViewOptions {
    std::string view = "orbit";
    std::optional<glm::dvec3> sensor;  // file coordinates

    void add(CLI::App& command);
    bool wanted() const { return view == "sensor"; }
    /// The view from where the scan was taken: an organised cloud's own camera, fitted to its
    /// grid (its size unless `sizeGiven`, then `width` x `height` with the same field of
    /// view); else from --sensor, the PCD VIEWPOINT or the E57 pose towards the points, at
    /// `width` x `height` and `fovyDegrees`. Throws subscan::Error naming `source` when the
    /// scan records no sensor and --sensor is not given.
    Camera camera(const LoadedScan& scan, const std::string& source, UpAxis up, int width,
                  int height, bool sizeGiven, double fovyDegrees) const;
};

}  // namespace subscan::cli
