#pragma once

#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "io/ScanLoader.h"

namespace subscan::cli {

/// Loads a scan for a command: a progress bar on stderr for big files on a terminal, then the
/// reader's warnings printed as "subscan: warning: ...".
LoadedScan loadScanForCommand(std::string_view source);

/// `--resolution full|half|auto` (RasterSettings::resolution), as render and bench take it.
void addResolutionOption(CLI::App& command, std::string& resolution);

}  // namespace subscan::cli
