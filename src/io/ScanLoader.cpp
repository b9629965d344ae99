#include "io/ScanLoader.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <numeric>
#include <string>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "io/E57Reader.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "io/OffReader.h"
#include "io/PcdReader.h"
#include "io/PlyReader.h"
#include "io/ReadContext.h"
#include "io/TextParsing.h"
#include "io/XyzReader.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "scan/SyntheticScenes.h"

namespace subscan {

namespace {

constexpr std::string_view kSyntheticPrefix = "synthetic:";

bool startsWith(std::span<const std::byte> file, std::string_view prefix) {
    return file.size() >= prefix.size() &&
           std::equal(prefix.begin(), prefix.end(), file.begin(),
                      [](char c, std::byte b) { return static_cast<char>(b) == c; });
}

/// PCD headers start with comment lines and then VERSION (or FIELDS/COLUMNS in old files).
bool looksLikePcd(std::span<const std::byte> file) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()),
                                std::min<std::size_t>(file.size(), 4096));
    std::size_t position = 0;
    while (position < text.size()) {
        const std::size_t end = std::min(text.find('\n', position), text.size());
        const std::string_view line = text.substr(position, end - position);
        position = end + 1;
        if (line.empty() || line == "\r" || line.front() == '#') {
            if (line.starts_with("# .PCD")) {
                return true;
            }
            continue;
        }
        return line.starts_with("VERSION") || line.starts_with("FIELDS") ||
               line.starts_with("COLUMNS");
    }
    return false;
}

/// OFF meshes open with a keyword: OFF, optionally prefixed by ST, C, N, 4 or n (COFF, NOFF,
/// STCNOFF...), then whitespace or the vertex counts. Their lines of numbers would otherwise
/// pass for a point list and fail on the first face line.
bool looksLikeOff(std::span<const std::byte> file) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()),
                                std::min<std::size_t>(file.size(), 16));
    const std::size_t keyword = text.find("OFF");
    if (keyword == std::string_view::npos ||
        text.substr(0, keyword).find_first_not_of("STCN4n") != std::string_view::npos) {
        return false;
    }
    const std::size_t after = keyword + 3;
    return after == text.size() || std::isspace(static_cast<unsigned char>(text[after])) != 0 ||
           text.substr(after).starts_with("BINARY");
}

std::string lowerExtension(const std::filesystem::path& path) {
    return asciiLowercase(path.extension().string());
}

}  // namespace

ScanFormat detectFormat(std::span<const std::byte> file, const std::filesystem::path& path) {
    if (startsWith(file, "ply\n") || startsWith(file, "ply\r\n")) {
        return ScanFormat::Ply;
    }
    if (startsWith(file, "LASF")) {
        return ScanFormat::Las;
    }
    if (startsWith(file, "ASTM-E57")) {
        return ScanFormat::E57;
    }
    if (looksLikePcd(file)) {
        return ScanFormat::Pcd;
    }
    if (looksLikeOff(file)) {
        return ScanFormat::Off;
    }
    // Content was not conclusive: the extension decides, and that reader explains what is wrong.
    const std::string extension = lowerExtension(path);
    if (extension == ".ply") {
        return ScanFormat::Ply;
    }
    if (extension == ".las" || extension == ".laz") {
        return ScanFormat::Las;
    }
    if (extension == ".pcd") {
        return ScanFormat::Pcd;
    }
    if (extension == ".e57") {
        return ScanFormat::E57;
    }
    if (extension == ".off") {
        return ScanFormat::Off;
    }
    if (extension == ".xyz" || extension == ".pts" || extension == ".txt" || extension == ".csv" ||
        extension == ".asc") {
        return ScanFormat::Xyz;
    }
    if (looksLikePointText(file)) {
        return ScanFormat::Xyz;
    }
    return ScanFormat::Unknown;
}

void ignoreZeroNormals(PointCloud& cloud, std::vector<std::string>& warnings) {
    if (!cloud.normals.empty() &&
        std::none_of(cloud.normals.begin(), cloud.normals.end(),
                     [](const glm::vec3& normal) { return glm::dot(normal, normal) > 0.0f; })) {
        cloud.normals.clear();
        warnings.push_back("its normals are all zero: they are ignored");
    }
}

LoadedScan decodeScan(std::span<const std::byte> file, ScanFormat format,
                      const std::function<void(double)>& progress, bool keepFilePrecision) {
    if (file.empty()) {
        throw Error("the file is empty");
    }
    ReadContext context;
    context.progress = progress;
    context.keepFilePrecision = keepFilePrecision;
    LoadedScan scan;
    switch (format) {
        case ScanFormat::Ply:
            scan.format = "ply";
            scan.cloud = readPly(file, context);
            break;
        case ScanFormat::Las:
            scan.format = "las";
            scan.cloud = readLas(file, context);
            break;
        case ScanFormat::Pcd:
            scan.format = "pcd";
            scan.cloud = readPcd(file, context);
            break;
        case ScanFormat::Xyz:
            scan.format = "xyz";
            scan.cloud = readXyz(file, context);
            break;
        case ScanFormat::E57:
            scan.format = "e57";
            scan.cloud = readE57(file, context);
            break;
        case ScanFormat::Off:
            scan.format = "off";
            scan.cloud = readOff(file, context);
            break;
        case ScanFormat::Unknown:
            throw Error(
                "its format is unknown: it is not PLY, LAS, LAZ, PCD, E57, OFF or a text list "
                "of coordinates");
    }
    ignoreZeroNormals(scan.cloud, context.warnings);
    keepResidualsWhereNeeded(scan.cloud);
    scan.formatDetail = std::move(context.formatDetail);
    scan.warnings = std::move(context.warnings);
    scan.sensor = std::move(context.sensor);
    scan.grid = std::move(context.grid);
    return scan;
}

LoadedScan loadScan(std::string_view source, const std::function<void(double)>& progress,
                    bool keepFilePrecision) {
    const auto start = std::chrono::steady_clock::now();
    LoadedScan scan;
    if (const std::filesystem::path path{std::string(source)};
        !source.starts_with(kSyntheticPrefix) && lod::isEpt(path)) {
        // Its sentences name the file they are about (ept.json, a hierarchy page, a tile).
        const std::unique_ptr<lod::NodeSource> ept = lod::openEpt(path);
        std::vector<std::size_t> every(ept->nodes().size());
        std::iota(every.begin(), every.end(), std::size_t{0});
        // Loaded whole: the bounds are the points' own, not the description's.
        scan.warnings = ept->info().warnings;
        scan.cloud = lod::loadNodes(*ept, every, scan.warnings);
        if (scan.cloud.size() == 0) {
            throw Error(fmt::format("{}: none of its {} nodes could be read ({})", source,
                                    every.size(), scan.warnings.back()));
        }
        scan.format = ept->info().format;
        scan.formatDetail = ept->info().formatDetail;
        if (progress) {
            progress(1.0);
        }
        scan.loadMilliseconds =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        return scan;
    }
    try {
        if (source.starts_with(kSyntheticPrefix)) {
            SyntheticSource synthetic = makeSyntheticSource(source.substr(kSyntheticPrefix.size()));
            if (synthetic.scanner.mode == ScannerSettings::Mode::Station) {
                scan.sensor =
                    SensorPose{stationPosition(*synthetic.scene, synthetic.scanner.station),
                               "the virtual station"};
            }
            scan.cloud = std::move(synthetic.points);
            scan.format = "synthetic";
            scan.formatDetail = fmt::format("built-in scene {}", source);
        } else {
            const std::filesystem::path path{std::string(source)};
            const MappedFile mapped(path);
            // A file shortened while it is read decodes zeros past its new end: whatever the
            // reader made of them, the truncation is what to report.
            const Error shrank(
                "the file became shorter while it was read (another program "
                "truncated or rewrote it); read it again once it is complete");
            try {
                scan = decodeScan(mapped.bytes(), detectFormat(mapped.bytes(), path), progress,
                                  keepFilePrecision);
            } catch (const Error&) {
                if (mapped.shrank()) {
                    throw shrank;
                }
                throw;
            }
            if (mapped.shrank()) {
                throw shrank;
            }
        }
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", source, error.what()));
    }
    scan.loadMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return scan;
}

}  // namespace subscan
