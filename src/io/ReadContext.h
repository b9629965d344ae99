#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/SensorView.h"

namespace subscan {

/// What a reader may report besides the cloud: progress for long loads, warnings about data it
/// had to skip and a description of the variant it read. Errors are thrown as subscan::Error.
struct ReadContext {
    /// Called with the fraction done (0..1) every few tens of thousands of points; may be empty.
    std::function<void(double)> progress;
    std::vector<std::string> warnings;
    /// Filled by the reader, e.g. "PLY 1.0 binary_little_endian" or "LAS 1.4, point format 7".
    std::string formatDetail;
    /// Where the sensor stood, when the file says (PCD VIEWPOINT, E57 pose).
    std::optional<SensorPose> sensor;
    /// The grid of an organised cloud (PCD HEIGHT > 1), with each kept point's cell.
    OrganisedGrid grid;
    /// Threads for readers that decode independent blocks (LAZ chunks); 0: one per core.
    unsigned decodeThreads = 0;
    /// Whether the cloud should give back the file's coordinates to the file's own precision
    /// (PointCloud::positionResiduals, where floats lose it): for writing them, not for drawing.
    bool keepFilePrecision = false;

    void reportProgress(std::size_t done, std::size_t total) const {
        if (progress && total > 0) {
            progress(static_cast<double>(done) / static_cast<double>(total));
        }
    }
};

}  // namespace subscan
