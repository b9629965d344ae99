#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Error.h"
#include "core/NormalEstimation.h"
#include "io/Las14Writer.h"
#include "io/LasWriter.h"
#include "io/PcdWriter.h"
#include "io/PlyWriter.h"
#include "io/RecordSourceSupport.h"
#include "io/TextParsing.h"
#include "io/WriterSupport.h"
#include "io/XyzWriter.h"
#include "lod/CopcWriter.h"
#include "lod/NodeSource.h"
#include "lod/OctreeIndexer.h"

namespace subscan::cli {

namespace {

struct ConvertOptions {
    std::string source;
    std::string output;
    bool estimateNormals = false;
};

/// A format convert writes, and what of a cloud it can hold besides positions, colour and
/// intensity (which all of them hold; LAS alone holds classification): whatever else the cloud has
/// is reported as not written.
struct OutputFormat {
    std::string_view extension;  // lowercase
    std::string_view name;
    void (*write)(const std::filesystem::path&, const LoadedScan&);
    bool normals;
    bool alphaAndFaces;
    bool classification;
};

constexpr std::array<OutputFormat, 4> kOutputFormats{{
    {".ply", "PLY",
     [](const std::filesystem::path& path, const LoadedScan& scan) { writePly(path, scan.cloud); },
     true, true, false},
    {".las", "LAS 1.2",
     [](const std::filesystem::path& path, const LoadedScan& scan) { writeLas(path, scan.cloud); },
     false, false, true},
    // The PCD VIEWPOINT is where the scan's sensor stood, where the input says.
    {".pcd", "PCD",
     [](const std::filesystem::path& path, const LoadedScan& scan) {
         writePcd(path, scan.cloud,
                  scan.sensor ? std::optional(scan.sensor->position) : std::nullopt);
     },
     true, false, false},
    {".xyz", "XYZ text",
     [](const std::filesystem::path& path, const LoadedScan& scan) { writeXyz(path, scan.cloud); },
     true, false, false},
}};

/// Outputs written from LAS 1.4 point records (io/PointRecordSource.h) rather than from a
/// loaded cloud: LAZ and COPC always, LAS when the input is LAS, LAZ, COPC or EPT (whose tiles
/// are LAZ), so that its integer coordinates and every attribute pass unchanged.
enum class RecordOutput { None, Las, Laz, Copc };

bool isLasFamily(const std::string& source) {
    if (!source.starts_with("synthetic:") && lod::isEpt(source)) {
        return true;
    }
    std::ifstream file(source, std::ios::binary);
    char signature[4] = {};
    return file.read(signature, 4) && std::string_view(signature, 4) == "LASF";
}

RecordOutput recordOutput(const std::filesystem::path& output, const std::string& source) {
    const std::string name = asciiLowercase(output.filename().string());
    if (name.ends_with(".copc.laz")) {
        return RecordOutput::Copc;
    }
    if (name.ends_with(".laz")) {
        return RecordOutput::Laz;
    }
    if (name.ends_with(".las") && isLasFamily(source)) {
        return RecordOutput::Las;
    }
    return RecordOutput::None;
}

struct RecordsWritten {
    std::uint64_t points = 0;
    bool everyAttributeKept = true;  // false where a warning said what was lost
};

/// Writes `source` as LAS 1.4, LAZ or COPC from its records.
RecordsWritten convertRecords(const std::string& source, const std::filesystem::path& output,
                              RecordOutput kind) {
    const std::unique_ptr<PointRecordSource> records = openPointRecordSource(source);
    const PointRecordSourceInfo& info = records->info();
    printSourceWarnings(info);
    const RecordsWritten written{info.pointCount, info.warnings.empty()};
    if (kind == RecordOutput::Copc) {
        lod::IndexSettings settings;
        settings.temporaryDirectory = std::filesystem::absolute(output).parent_path();
        lod::writeCopc(*records, output, settings);
        return written;
    }
    std::vector<std::byte> all;
    all.reserve(info.pointCount * info.format.recordLength());
    while (records->read(all, std::size_t{1} << 20) > 0) {
    }
    if (kind == RecordOutput::Laz) {
        writeLaz14(output, info, all);
    } else {
        writeLas14(output, info, all);
    }
    return written;
}

/// The format named by the output's extension (any case), or nullptr.
const OutputFormat* outputFormat(const std::filesystem::path& output) {
    const std::string extension = asciiLowercase(output.extension().string());
    const auto* format = std::find_if(
        kOutputFormats.begin(), kOutputFormats.end(),
        [&](const OutputFormat& candidate) { return candidate.extension == extension; });
    return format == kOutputFormats.end() ? nullptr : format;
}

std::string supportedExtensions() {
    std::string list;
    for (const OutputFormat& format : kOutputFormats) {
        list += list.empty() ? "" : ", ";
        list += format.extension;
    }
    return list;
}

/// Data is dropped only with a warning, as loaders warn about what they could not read.
void warnAboutWhatIsNotWritten(const std::string& output, const OutputFormat& format,
                               const LoadedScan& scan) {
    const PointCloud& cloud = scan.cloud;
    const auto warn = [&](std::string_view what) {
        fmt::print(stderr, "subscan: warning: {}: {} output holds no {}; they are not written\n",
                   output, format.name, what);
    };
    // LAS holds whole intensities in 0..65535 (writeLas rounds and clamps the others).
    if (format.extension == ".las" && !fitIntensityWords(cloud.intensities)) {
        fmt::print(stderr, "subscan: warning: {}\n", intensitiesNotKept(output));
    }
    // Every format written from a cloud holds its 8-bit colour only. PLY could declare ushort
    // colour, but Open3D's reader divides any PLY colour by 255, and 16-bit colour would break it.
    if (cloud.colorCutTo8Bits) {
        // Not "16-bit": E57 colour limits span any width (12-bit is common).
        fmt::print(stderr,
                   "subscan: warning: {}: {} output is written with 8-bit colour, so the input's "
                   "colour of more than 8 bits a channel is cut to 8 bits\n",
                   output, format.name);
    }
    if (!scan.grid.empty()) {
        fmt::print(stderr,
                   "subscan: warning: {}: the input's organised grid ({} x {}) is not kept: the "
                   "points are written as a list\n",
                   output, scan.grid.width, scan.grid.height);
    }
    if (cloud.hasNormals() && !format.normals) {
        warn("normals");
    }
    if (cloud.hasClassifications() && !format.classification) {
        warn("classification codes");
    }
    if (!format.alphaAndFaces) {
        if (hasTranslucentColors(cloud)) {
            warn("colour alpha values");
        }
        if (!cloud.triangles.empty()) {
            warn(fmt::format("faces ({} of them)", cloud.triangles.size()));
        }
    }
}

int runConvert(const ConvertOptions& options) {
    const std::filesystem::path output = options.output;
    if (!options.source.starts_with("synthetic:") && sameFile(output, options.source)) {
        throw Error(fmt::format(
            "{}: refusing to write the converted scan over its input; choose another output path",
            options.output));
    }
    if (const RecordOutput kind = recordOutput(output, options.source);
        kind != RecordOutput::None) {
        if (options.estimateNormals) {
            throw Error(fmt::format(
                "{}: --estimate-normals writes PLY, PCD or XYZ; for LAZ or COPC with estimated "
                "normals convert to PLY with --estimate-normals, then that PLY to LAZ or COPC "
                "(its normals become the extra bytes NormalX, NormalY, NormalZ)",
                options.output));
        }
        const RecordsWritten written = convertRecords(options.source, output, kind);
        fmt::print("{}: {} points written as {} (from {}), {}\n", options.output, written.points,
                   kind == RecordOutput::Copc  ? "COPC"
                   : kind == RecordOutput::Laz ? "LAZ 1.4"
                                               : "LAS 1.4",
                   options.source,
                   written.everyAttributeKept ? "every attribute as LAS 1.4 holds it"
                                              : "less what the warnings above say");
        return 0;
    }
    const OutputFormat& format = *outputFormat(output);  // the option's check accepted it
    // The file's coordinates to its own precision, not only as floats hold them.
    LoadedScan scan = loadScanForCommand(options.source, /*keepFilePrecision=*/true);
    if (options.estimateNormals) {
        if (!format.normals) {
            throw Error(
                fmt::format("{}: {} cannot hold normals; --estimate-normals needs PLY, "
                            "PCD or XYZ",
                            options.output, format.name));
        }
        // In place of the file's own, if any: asked for, they are the estimate's.
        std::optional<glm::dvec3> sensor;
        if (scan.sensor) {
            sensor = scan.sensor->position;
        }
        scan.cloud.normals = estimateNormals(scan.cloud, sensor);
    }
    format.write(output, scan);
    warnAboutWhatIsNotWritten(options.output, format, scan);
    fmt::print("{}: {} points written as {} (from {})\n", options.output, scan.cloud.size(),
               format.name, options.source);
    return 0;
}

}  // namespace

Command addConvertCommand(CLI::App& parent) {
    auto options = std::make_shared<ConvertOptions>();
    CLI::App* convert = parent.add_subcommand(
        "convert",
        "Write a scan as PLY, LAS, LAZ, COPC, PCD or XYZ text, with its colour, intensity and "
        "normals");
    convert->add_option("scan", options->source, "Scan file, or synthetic:NAME")->required();
    convert
        ->add_option("-o,--output", options->output,
                     fmt::format("File to write; its extension picks the format ({}, .laz, "
                                 ".copc.laz; LAS, LAZ and COPC inputs keep their coordinates "
                                 "and attributes exactly)",
                                 supportedExtensions()))
        ->required()
        ->check(
            [](const std::string& path) -> std::string {
                return outputFormat(path) != nullptr || asciiLowercase(path).ends_with(".laz")
                           ? std::string()
                           : fmt::format(
                                 "'{}' has no extension of a format convert writes ({}, "
                                 ".laz, .copc.laz)",
                                 path, supportedExtensions());
            },
            "FILE");
    convert->add_flag("--estimate-normals", options->estimateNormals,
                      "Write normals estimated from each point's neighbours (PCA), facing the "
                      "sensor where the file records one (PLY, PCD and XYZ output)");
    return {convert, [options] { return runConvert(*options); }};
}

}  // namespace subscan::cli
