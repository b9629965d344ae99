#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/Commands.h"
#include "sss/MaterialLibrary.h"

namespace subscan::cli {

namespace {

struct MaterialsOptions {
    bool json = false;
};

std::string rgbColumn(const std::optional<Rgb>& value) {
    return value ? fmt::format("{:g} {:g} {:g}", (*value)[0], (*value)[1], (*value)[2]) : "-";
}

int runMaterials(const MaterialsOptions& options) {
    const std::vector<Material>& materials = materialLibrary();
    if (options.json) {
        nlohmann::json list = nlohmann::json::array();
        for (const Material& material : materials) {
            list.push_back(materialJson(material));
        }
        fmt::print("{}\n", list.dump(2));
        return 0;
    }
    fmt::print("{:<16} {:>4}  {:<18} {:<22} {:<16} {}\n", "name", "eta", "σs′ RGB (1/mm)",
               "σa RGB (1/mm)", "Rd RGB", "Gaussians (largest σ)");
    for (const Material& material : materials) {
        const GaussianSet& set = material.gaussians;
        fmt::print("{:<16} {:>4g}  {:<18} {:<22} {:<16} {}{} ({:.3g} mm)\n", material.name,
                   material.eta, rgbColumn(material.sigmaSPrime), rgbColumn(material.sigmaA),
                   rgbColumn(material.rd), set.gaussians.size(),
                   set.cumulative ? " cumulative" : "", std::sqrt(set.largestVarianceMm2()));
    }
    fmt::print("\n`subscan materials --json` lists each set's variances (mm²) and RGB weights.\n");
    return 0;
}

}  // namespace

Command addMaterialsCommand(CLI::App& parent) {
    auto options = std::make_shared<MaterialsOptions>();
    CLI::App* materials = parent.add_subcommand(
        "materials", "The material library: measured coefficients and Gaussian sets");
    materials->add_flag("--json", options->json, "Machine-readable output");
    return {materials, [options] { return runMaterials(*options); }};
}

}  // namespace subscan::cli
