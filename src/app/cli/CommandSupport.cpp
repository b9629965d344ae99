#include "app/cli/CommandSupport.h"

#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "app/ProgressBar.h"

namespace subscan::cli {

LoadedScan loadScanForCommand(std::string_view source) {
    constexpr std::uintmax_t kProgressBarBytes = 50u << 20;
    std::error_code ignored;
    const std::uintmax_t bytes = std::filesystem::file_size(std::string(source), ignored);
    ProgressBar bar("loading", !ignored && bytes > kProgressBarBytes);
    LoadedScan scan = loadScan(source, [&](double fraction) { bar.update(fraction); });
    for (const std::string& warning : scan.warnings) {
        fmt::print(stderr, "subscan: warning: {}: {}\n", source, warning);
    }
    return scan;
}

void addResolutionOption(CLI::App& command, std::string& resolution) {
    command
        .add_option("--resolution", resolution,
                    "Pixels the surface is reconstructed at: full (default) | half | auto (half "
                    "while the points are 4 or more pixels apart)")
        ->check(CLI::IsMember({"full", "half", "auto"}));
}

}  // namespace subscan::cli
