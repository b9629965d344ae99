#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Spacing.h"

namespace subscan::cli {

namespace {

struct InfoOptions {
    std::string source;
    bool json = false;
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

int runInfo(const InfoOptions& options) {
    const LoadedScan scan = loadScanForCommand(options.source);
    const PointCloud& cloud = scan.cloud;
    const double spacing = estimateSpacing(cloud);
    const glm::dvec3& lo = cloud.bounds.min;
    const glm::dvec3& hi = cloud.bounds.max;

    if (options.json) {
        const nlohmann::json info = {
            {"format", scan.format},
            {"points", cloud.size()},
            {"bounds_min", {lo.x, lo.y, lo.z}},
            {"bounds_max", {hi.x, hi.y, hi.z}},
            {"attributes", attributeNames(cloud)},
            {"faces", cloud.triangles.size()},
            {"spacing", spacing},
            {"load_ms", scan.loadMilliseconds},
        };
        fmt::print("{}\n", info.dump(2));
        return 0;
    }
    const glm::dvec3 size = hi - lo;
    fmt::print("{}\n", options.source);
    fmt::print("  format      {}\n", scan.formatDetail);
    fmt::print("  points      {}\n", cloud.size());
    fmt::print("  faces       {}\n", cloud.triangles.size());
    fmt::print("  attributes  {}\n", fmt::join(attributeNames(cloud), ", "));
    fmt::print("  bounds min  {:.12g} {:.12g} {:.12g}\n", lo.x, lo.y, lo.z);
    fmt::print("  bounds max  {:.12g} {:.12g} {:.12g}\n", hi.x, hi.y, hi.z);
    fmt::print("  size        {:.6g} x {:.6g} x {:.6g}\n", size.x, size.y, size.z);
    fmt::print("  spacing     {:.6g} (median nearest-neighbour distance)\n", spacing);
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
    return {info, [options] { return runInfo(*options); }};
}

}  // namespace subscan::cli
