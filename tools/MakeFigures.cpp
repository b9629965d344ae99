// Renders the documentation's figures: the stages of the surface pipeline side by side (like the
// paper's Figure 2), a points/splats/surface comparison, and the surface beside marble and skin
// (like the paper's Figure 8), the two scattering paths under a grazing key light, shadows of a
// side light, and light through thin parts lit from behind. Run by scripts/make-figures.sh.
//   subscan_figures stages|compare|materials|single|shadows|backlit SCAN OUT.png [--yaw D]
//                   [--pitch D] [--distance F] [--size W H]
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "core/Camera.h"
#include "core/Error.h"
#include "gpu/GlContext.h"
#include "io/Image.h"
#include "io/ScanLoader.h"
#include "render/Renderer.h"

namespace subscan {
namespace {

struct Panel {
    RenderMode mode;
    Stage stage;
    std::string material = {};  // sss panels
    ScatteringMethod method = ScatteringMethod::Gaussian;
    bool keyLight = true;   // shadows: the side light shines
    bool lightMaps = true;  // shadows: it casts shadows; backlit: transmission, light_map
};

/// Side-by-side tiles, `columns` per row, separated by a `gap` of background.
Image8 montage(const std::vector<std::vector<std::uint8_t>>& tiles, int width, int height,
               int columns, int gap, std::uint8_t background) {
    const int rows = (static_cast<int>(tiles.size()) + columns - 1) / columns;
    Image8 out{columns * width + (columns - 1) * gap, rows * height + (rows - 1) * gap, 4, {}};
    out.pixels.assign(static_cast<std::size_t>(out.width * out.height * 4), background);
    for (std::size_t t = 0; t < tiles.size(); ++t) {
        const int x0 = static_cast<int>(t % columns) * (width + gap);
        const int y0 = static_cast<int>(t / columns) * (height + gap);
        for (int y = 0; y < height; ++y) {
            std::copy_n(
                tiles[t].begin() + static_cast<std::ptrdiff_t>(y * width * 4), width * 4,
                out.pixels.begin() + static_cast<std::ptrdiff_t>(((y0 + y) * out.width + x0) * 4));
        }
    }
    return out;
}

int run(int argc, char** argv) {
    if (argc < 4) {
        std::fprintf(stderr,
                     "usage: subscan_figures stages|compare|materials|single|shadows|backlit SCAN "
                     "OUT.png [--yaw D] [--pitch D] [--distance F] [--size W H]\n");
        return 2;
    }
    const std::string_view kind = argv[1];
    OrbitView orbit;
    int width = 480, height = 540;
    for (int i = 4; i < argc; ++i) {
        const std::string_view option = argv[i];
        if (option == "--yaw" && i + 1 < argc) {
            orbit.yawDegrees = std::stod(argv[++i]);
        } else if (option == "--pitch" && i + 1 < argc) {
            orbit.pitchDegrees = std::stod(argv[++i]);
        } else if (option == "--distance" && i + 1 < argc) {
            orbit.distance = std::stod(argv[++i]);
        } else if (option == "--size" && i + 2 < argc) {
            width = std::stoi(argv[++i]);
            height = std::stoi(argv[++i]);
        } else {
            std::fprintf(stderr, "subscan_figures: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    std::vector<Panel> panels;
    int columns = 2;
    if (kind == "stages") {
        panels = {{RenderMode::Points, Stage::Final},       {RenderMode::Surface, Stage::Depth},
                  {RenderMode::Surface, Stage::Visibility}, {RenderMode::Surface, Stage::Pull},
                  {RenderMode::Surface, Stage::Push},       {RenderMode::Surface, Stage::Fill},
                  {RenderMode::Surface, Stage::Normals},    {RenderMode::Surface, Stage::Final}};
        columns = 4;
    } else if (kind == "materials") {
        panels = {{RenderMode::Surface, Stage::Final},
                  {RenderMode::Sss, Stage::Final, "marble-jimenez"},
                  {RenderMode::Sss, Stage::Final, "skin-jimenez"}};
        columns = 3;
    } else if (kind == "single") {
        panels = {{RenderMode::Surface, Stage::Final},
                  {RenderMode::Sss, Stage::Final, "marble-jimenez", ScatteringMethod::Gaussian},
                  {RenderMode::Sss, Stage::Final, "marble-jimenez", ScatteringMethod::Single},
                  {RenderMode::Sss, Stage::Final, "marble-jimenez", ScatteringMethod::Both}};
        columns = 4;
    } else if (kind == "shadows") {
        panels = {{RenderMode::Surface, Stage::Final, {}, {}, false},
                  {RenderMode::Surface, Stage::Final, {}, {}, true, false},
                  {RenderMode::Surface, Stage::Final, {}, {}, true, true}};
        columns = 3;
    } else if (kind == "backlit") {
        panels = {
            {RenderMode::Sss, Stage::Final, "skin-deon", ScatteringMethod::Gaussian, true, false},
            {RenderMode::Sss, Stage::Final, "skin-deon", ScatteringMethod::Gaussian},
            {RenderMode::Sss, Stage::Final, "marble", ScatteringMethod::Single, true, false},
            {RenderMode::Sss, Stage::Final, "marble", ScatteringMethod::Single}};
        columns = 4;
    } else if (kind == "compare") {
        panels = {{RenderMode::Points, Stage::Final},
                  {RenderMode::Splats, Stage::Final},
                  {RenderMode::Surface, Stage::Final}};
        columns = 3;
    } else {
        std::fprintf(stderr, "subscan_figures: unknown figure %s\n", argv[1]);
        return 2;
    }

    const LoadedScan scan = loadScan(argv[2]);
    const Camera camera = orbitCamera(scan.cloud.bounds, orbit, width, height, 40.0);
    const auto context = createHeadlessContext();
    Renderer renderer(*context, scan.cloud);
    std::vector<std::vector<std::uint8_t>> tiles;
    for (const Panel& panel : panels) {
        RenderSettings settings;
        settings.raster.mode = panel.mode;
        settings.raster.stage = panel.stage;
        settings.raster.pointSize = 3.0f;
        settings.raster.backgroundSrgb = glm::vec3(0.12f);
        if (kind == "materials") {
            // A key light from the upper left besides the head light: translucency shows where
            // light and shadow meet.
            settings.shading.headLight = glm::vec3(0.35f);
            settings.shading.lights.push_back({{-1.0f, 1.0f, 0.6f}, glm::vec3(0.9f)});
        }
        if (kind == "single") {
            // A grazing key light from the left, nearly in the image plane, and a dim head
            // light: single scattering grows towards grazing light where the diffuse fades.
            settings.shading.headLight = glm::vec3(0.15f);
            settings.shading.ambient = glm::vec3(0.05f);
            settings.shading.lights.push_back({{-1.0f, 0.25f, 0.15f}, glm::vec3(1.2f)});
        }
        if (kind == "shadows") {
            // Today's default (head light and ambient) beside a key light from the left.
            if (panel.keyLight) {
                settings.shading.headLight = glm::vec3(0.25f);
                settings.shading.ambient = glm::vec3(0.08f);
                settings.shading.lights.push_back({{-1.0f, 0.5f, 0.35f}, glm::vec3(0.9f)});
            }
            settings.shading.shadows = panel.lightMaps;
        }
        if (kind == "backlit") {
            // A light from behind and above, a dim head light: thin parts glow where the light
            // comes through (transmission for the blur, the light map's entries for single
            // scattering); without them, only the head light's share is left.
            settings.shading.headLight = glm::vec3(0.2f);
            settings.shading.ambient = glm::vec3(0.03f);
            settings.shading.lights.push_back({{0.3f, 0.5f, -1.0f}, glm::vec3(2.0f)});
            settings.scattering.scale = 2.0f;
            settings.scattering.transmission = panel.lightMaps;
            settings.scattering.lightPath =
                panel.lightMaps ? LightPath::LightMap : LightPath::Screen;
        }
        if (!panel.material.empty()) {
            settings.scattering.material = panel.material;
        }
        settings.scattering.method = panel.method;
        renderer.render(camera, settings);
        tiles.push_back(renderer.readImage());
    }
    writePng(argv[3], montage(tiles, width, height, columns, 4, 255));
    return 0;
}

}  // namespace
}  // namespace subscan

int main(int argc, char** argv) {
    try {
        return subscan::run(argc, argv);
    } catch (const subscan::Error& error) {
        std::fprintf(stderr, "subscan_figures: %s\n", error.what());
        return 1;
    }
}
