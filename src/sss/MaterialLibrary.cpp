#include "sss/MaterialLibrary.h"

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

std::vector<Material> builtInMaterials() {
    std::vector<Material> materials;
    materials.push_back({"skin-deon",
                         "skin, 6 Gaussians (d'Eon & Luebke 2007, GPU Gems 3 ch. 14)",
                         1.4,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0064, {0.233, 0.455, 0.649}},
                           {0.0484, {0.100, 0.336, 0.344}},
                           {0.187, {0.118, 0.198, 0.0}},
                           {0.567, {0.113, 0.007, 0.007}},
                           {1.99, {0.358, 0.004, 0.0}},
                           {7.41, {0.078, 0.0, 0.0}}},
                          false}});
    materials.push_back({"skin-jimenez",
                         "skin, 4 cumulative Gaussians (Jimenez et al. 2009)",
                         1.4,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0, {0.2405, 0.4474, 0.6158}},
                           {0.0516500, {0.1159, 0.3662, 0.3439}},
                           {0.2719281, {0.1836, 0.1864, 0.0}},
                           {2.0062639, {0.4600, 0.0, 0.0403}}},
                          true}});
    materials.push_back({"marble-jimenez",
                         "marble, 4 cumulative Gaussians (Jimenez et al. 2009)",
                         1.5,
                         std::nullopt,
                         std::nullopt,
                         std::nullopt,
                         {{{0.0362209, {0.0545, 0.1245, 0.2177}},
                           {0.1144506, {0.2437, 0.2435, 0.1890}},
                           {0.4555844, {0.3105, 0.3158, 0.3742}},
                           {3.4833196, {0.3913, 0.3161, 0.2190}}},
                          true}});
    return materials;
}

}  // namespace

const std::vector<Material>& materialLibrary() {
    static const std::vector<Material> materials = builtInMaterials();
    return materials;
}

const Material& findMaterial(std::string_view name) {
    std::string known;
    for (const Material& material : materialLibrary()) {
        if (material.name == name) {
            return material;
        }
        known += (known.empty() ? "" : ", ") + material.name;
    }
    throw Error(fmt::format("there is no material '{}'; the materials are {}", name, known));
}

}  // namespace subscan
