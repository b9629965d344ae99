#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/Commands.h"
#include "sss/MaterialLibrary.h"
#include "sss/ProfileFit.h"

namespace subscan::cli {

namespace {

struct FitProfileOptions {
    std::string material;
    int gaussians = 0;
    std::string profile = "dipole";
    bool json = false;
};

int runFitProfile(const FitProfileOptions& options) {
    const Material& material = findMaterial(options.material);
    const ProfileModel model =
        options.profile == "burley" ? ProfileModel::Burley : ProfileModel::Dipole;
    const ProfileFit fit = fitGaussians(diffusionProfile(material, model), options.gaussians);
    const Rgb& error = fit.quality.fitError;

    if (options.json) {
        fmt::print("{}\n", profileFitJson(material, fit).dump(2));
        return 0;
    }
    fmt::print("{}: {} Gaussians fitted to the {} profile, normalised to unit energy per channel\n",
               material.name, fit.gaussians.gaussians.size(),
               model == ProfileModel::Dipole ? "dipole" : "Burley");
    fmt::print("  {:>14}  {:>8} {:>8} {:>8}\n", "variance (mm²)", "R", "G", "B");
    for (const Gaussian& term : fit.gaussians.gaussians) {
        fmt::print("  {:>14.6g}  {:>8.5f} {:>8.5f} {:>8.5f}\n", term.varianceMm2, term.weight[0],
                   term.weight[1], term.weight[2]);
    }
    fmt::print("  {:>14}  {:>8.5f} {:>8.5f} {:>8.5f}\n", "fit error", error[0], error[1], error[2]);
    fmt::print(
        "  (relative L2 error over r ≤ {:.4g} mm, the radius holding 99.9 % of the widest "
        "channel's energy)\n",
        fit.quality.rMaxMm);
    return 0;
}

}  // namespace

Command addFitProfileCommand(CLI::App& parent) {
    auto options = std::make_shared<FitProfileOptions>();
    CLI::App* command = parent.add_subcommand(
        "fit-profile", "Fit N Gaussians to a measured material's diffusion profile");
    command
        ->add_option("--material", options->material,
                     "A material with σs′ and σa (see `subscan materials`)")
        ->required();
    command
        ->add_option("--gaussians", options->gaussians,
                     fmt::format("How many Gaussians (1 to {})", kMaxFittedGaussians))
        ->required()
        ->check(CLI::Range(1, kMaxFittedGaussians));
    command
        ->add_option("--profile", options->profile,
                     "Jensen's dipole or Burley's normalized diffusion (default dipole)")
        ->check(CLI::IsMember({"dipole", "burley"}));
    command->add_flag("--json", options->json, "Machine-readable output");
    return {command, [options] { return runFitProfile(*options); }};
}

}  // namespace subscan::cli
