#pragma once

#include <string_view>

#include "io/ScanLoader.h"

namespace subscan::cli {

/// Loads a scan for a command: a progress bar on stderr for big files on a terminal, then the
/// reader's warnings printed as "subscan: warning: ...".
LoadedScan loadScanForCommand(std::string_view source);

}  // namespace subscan::cli
