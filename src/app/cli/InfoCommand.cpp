#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Spacing.h"
#include "lod/NodeSource.h"

namespace subscan::cli {

namespace {

struct InfoOptions {
    std::string source;
    bool json = false;
    std::string lod = "auto";
};

std::vector<std::string> attributeNames(const PointCloud& cloud) {
    std::vector<std::string> names{"position"};
    if (cloud.hasColors()) {
        names.emplace_back("color");
    }
    if (cloud.hasNormals()) {
        names.emplace_back("normal");
    }
    if (cloud.hasIntensities()) {
        names.emplace_back("intensity");
    }
    if (cloud.hasClassifications()) {
        names.emplace_back("classification");
    }
    return names;
}

/// What info reports of a scan, whether loaded whole or read from its octree's hierarchy.
struct ScanSummary {
    LoadedScan scan;  // whole, or a streamed source's densest deepest node
    std::uint64_t points = 0;
    double spacing = 0.0;
    std::string spacingWhere;                // "" for the whole cloud, else the node measured
    std::vector<std::uint64_t> levelPoints;  // streamed sources: points per level
};

/// A streamed source without reading its points: the hierarchy's counts, the header's bounds,
/// and the attributes and spacing of the deepest level's largest node (a node of the deepest
/// level holds every point its ancestors left there: the survey's full density).
ScanSummary streamedSummary(const lod::NodeSource& source) {
    const auto start = std::chrono::steady_clock::now();
    const std::span<const lod::StreamedNode> nodes = source.nodes();
    std::size_t densest = nodes.size() - 1;
    for (std::size_t i = nodes.size(); i-- > 0 && nodes[i].key.level == nodes.back().key.level;) {
        if (nodes[i].pointCount >= nodes[densest].pointCount) {
            densest = i;
        }
    }
    ScanSummary summary;
    try {
        summary.scan.cloud = source.load(densest);
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", source.info().name, error.what()));
    }
    summary.scan.cloud.bounds = source.info().bounds;
    summary.scan.format = source.info().format;
    summary.scan.formatDetail = source.info().formatDetail;
    summary.points = source.info().points;
    summary.spacing = estimateSpacing(summary.scan.cloud);
    summary.spacingWhere = lod::nodeName(nodes[densest].key);
    for (const lod::StreamedNode& node : nodes) {
        summary.levelPoints.resize(
            std::max(summary.levelPoints.size(), static_cast<std::size_t>(node.key.level) + 1), 0);
        summary.levelPoints[static_cast<std::size_t>(node.key.level)] += node.pointCount;
    }
    summary.scan.loadMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    for (const std::string& warning : source.info().warnings) {
        fmt::print(stderr, "subscan: warning: {}: {}\n", source.info().name, warning);
    }
    return summary;
}

int runInfo(const InfoOptions& options) {
    const std::unique_ptr<lod::NodeSource> streamed =
        lod::openStreamed(options.source, lod::parseLodMode(options.lod));
    ScanSummary summary;
    if (streamed) {
        summary = streamedSummary(*streamed);
    } else {
        summary.scan = loadScanForCommand(options.source);
        summary.points = summary.scan.cloud.size();
        summary.spacing = estimateSpacing(summary.scan.cloud);
    }
    const LoadedScan& scan = summary.scan;
    const PointCloud& cloud = scan.cloud;
    const double spacing = summary.spacing;
    const glm::dvec3& lo = cloud.bounds.min;
    const glm::dvec3& hi = cloud.bounds.max;

    if (options.json) {
        nlohmann::json info = {
            {"format", scan.format},
            // "las" stands for LAS, LAZ, COPC and EPT alike (it says how points are read): the
            // text line, as the plain output prints it, tells them apart.
            {"format_detail", scan.formatDetail},
            {"points", summary.points},
            {"bounds_min", {lo.x, lo.y, lo.z}},
            {"bounds_max", {hi.x, hi.y, hi.z}},
            {"attributes", attributeNames(cloud)},
            {"faces", cloud.triangles.size()},
            {"spacing", spacing},
            {"load_ms", scan.loadMilliseconds},
        };
        if (streamed) {
            info["level_points"] = summary.levelPoints;
            info["root_spacing"] = streamed->info().cube.rootSpacing;
        }
        fmt::print("{}\n", info.dump(2));
        return 0;
    }
    const glm::dvec3 size = hi - lo;
    fmt::print("{}\n", options.source);
    fmt::print("  format      {}\n", scan.formatDetail);
    fmt::print("  points      {}\n", summary.points);
    if (streamed) {
        fmt::print("  levels      {} points per level (streamed: read from the hierarchy)\n",
                   fmt::join(summary.levelPoints, ", "));
    }
    fmt::print("  faces       {}\n", cloud.triangles.size());
    fmt::print("  attributes  {}\n", fmt::join(attributeNames(cloud), ", "));
    fmt::print("  bounds min  {:.12g} {:.12g} {:.12g}\n", lo.x, lo.y, lo.z);
    fmt::print("  bounds max  {:.12g} {:.12g} {:.12g}\n", hi.x, hi.y, hi.z);
    fmt::print("  size        {:.6g} x {:.6g} x {:.6g}\n", size.x, size.y, size.z);
    fmt::print("  spacing     {:.6g} (median nearest-neighbour distance{})\n", spacing,
               summary.spacingWhere.empty() ? "" : " in " + summary.spacingWhere);
    fmt::print("  load time   {:.1f} ms\n", scan.loadMilliseconds);
    return 0;
}

}  // namespace

Command addInfoCommand(CLI::App& parent) {
    auto options = std::make_shared<InfoOptions>();
    CLI::App* info = parent.add_subcommand("info",
                                           "What is in a scan: count, bounds, attributes, "
                                           "spacing");
    info->add_option("scan", options->source, "Scan file, or synthetic:NAME")->required();
    info->add_flag("--json", options->json, "Machine-readable output");
    info->add_option("--lod", options->lod,
                     "auto: describe a COPC file or EPT dataset from its hierarchy, reading one "
                     "node's points; off: read every point")
        ->check(CLI::IsMember({"auto", "on", "off"}));
    return {info, [options] { return runInfo(*options); }};
}

}  // namespace subscan::cli
