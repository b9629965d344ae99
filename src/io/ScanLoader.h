#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/PointCloud.h"
#include "core/SensorView.h"

namespace subscan {

enum class ScanFormat { Ply, Las, Pcd, Xyz, E57, Off, Unknown };

/// Picks the reader: by content (magic bytes) first, by file extension second.
ScanFormat detectFormat(std::span<const std::byte> file, const std::filesystem::path& path);

struct LoadedScan {
    PointCloud cloud;
    std::string format;        // "ply", "las", "pcd", "xyz", "e57" or "synthetic"
    std::string formatDetail;  // e.g. "PLY 1.0 binary_little_endian"
    std::vector<std::string> warnings;
    double loadMilliseconds = 0.0;     // reading and decoding, nothing after
    std::optional<SensorPose> sensor;  // where the file says the sensor stood
    OrganisedGrid grid;                // an organised cloud's grid (empty when unorganised)
    /// A streamed view's points (lod::loadStreamedScan): per point, the spacing of the finest
    /// level of detail the view loaded where it lies (scene units), which its local spacing
    /// is at least (estimatePointSpacing); 0 where the survey holds nothing deeper there (the
    /// scan's own spacing); empty for a scan loaded whole.
    std::vector<float> levelSpacing;
};

/// Loads a scan file, or scans a built-in scene for "synthetic:NAME[?points=N][&noise=X]"
/// (see makeSyntheticScene).
/// Throws subscan::Error with one sentence that names the source and the problem.
/// `progress` (may be empty) receives the fraction done while a file is decoded.
/// `keepFilePrecision`: the cloud gives back the file's coordinates to the file's own precision
/// where floats would lose it (PointCloud::positionResiduals), as writers of files need; the
/// float positions, what the renderer draws, are the same either way.
LoadedScan loadScan(std::string_view source, const std::function<void(double)>& progress = {},
                    bool keepFilePrecision = false);

/// Some exporters fill the normal fields with zeros: no direction at all, which would shade the
/// whole surface flat. Such normals count as absent (they are estimated as for a file without
/// them), with a warning.
void ignoreZeroNormals(PointCloud& cloud, std::vector<std::string>& warnings);

/// Decodes an in-memory file of a known format; what loadScan does after mapping the file.
/// Errors are not prefixed with a file name.
LoadedScan decodeScan(std::span<const std::byte> file, ScanFormat format,
                      const std::function<void(double)>& progress = {},
                      bool keepFilePrecision = false);

}  // namespace subscan
