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

}  // namespace subscan::cli
