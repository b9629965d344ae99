// subscan.evaluate, materials, fit_profile and scan: the eval, materials, fit-profile and scan
// commands as functions returning what their --json prints (scan: the Cloud it would write).
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/Srgb.h"
#include "eval/Evaluation.h"
#include "gpu/GlContext.h"
#include "io/ScanLoader.h"
#include "python/Bindings.h"
#include "python/JsonConversion.h"
#include "scan/Scene.h"
#include "scan/SyntheticScenes.h"
#include "scan/VirtualScanner.h"
#include "sss/MaterialLibrary.h"
#include "sss/ProfileFit.h"

namespace py = pybind11;

namespace subscan::python {

namespace {

constexpr std::string_view kSynthetic = "synthetic:";
/// The albedo the ground truth of a mesh shows, given to its points too so that PSNR compares
/// geometry and shading, not a colour convention (as `subscan eval`).
constexpr float kMeshAlbedo = 0.7f;

/// Calls `function` and turns the library's errors into ValueError: for functions whose only
/// input is the caller's arguments.
template <class Function>
auto argumentErrors(Function&& function) {
    try {
        return function();
    } catch (const Error& error) {
        throw py::value_error(error.what());
    }
}

/// `subscan materials --json`.
py::list materials() {
    py::list list;
    for (const Material& material : materialLibrary()) {
        list.append(toPython(materialJson(material)));
    }
    return list;
}

/// `subscan fit-profile --material M --gaussians N [--profile P] --json`.
py::object fitProfile(const std::string& materialName, int gaussians, const std::string& profile) {
    checkRange(gaussians, 1, kMaxFittedGaussians, "gaussians");
    if (profile != "dipole" && profile != "burley") {
        throw py::value_error(fmt::format("profile '{}' is not dipole or burley", profile));
    }
    const Material& material =
        argumentErrors([&]() -> const Material& { return findMaterial(materialName); });
    const ProfileModel model = profile == "burley" ? ProfileModel::Burley : ProfileModel::Dipole;
    const RadialProfile radial = argumentErrors([&] { return diffusionProfile(material, model); });
    ProfileFit fit;
    {
        const py::gil_scoped_release release;
        fit = fitGaussians(radial, gaussians);
    }
    return toPython(profileFitJson(material, fit));
}

/// A mesh argument: a Cloud with triangles, or a file to load.
CloudHandle meshArgument(const py::handle& argument, std::string_view command) {
    CloudHandle mesh;
    std::string source = "the cloud";
    if (py::isinstance<CloudData>(argument)) {
        mesh = argument.cast<CloudHandle>();
    } else {
        source = pathArgument(argument);
        LoadedScan scan;
        {
            const py::gil_scoped_release release;
            scan = loadScan(source);
        }
        warnAll(source, scan.warnings);
        mesh = std::make_shared<CloudData>(std::move(scan.cloud), scan.format);
    }
    if (mesh->cloud().triangles.empty()) {
        throw Error(fmt::format("{}: has no faces; {} needs a triangle mesh", source, command));
    }
    return mesh;
}

/// `subscan scan SCENE -o OUT.ply [options]`, returning the cloud it would write.
CloudHandle scanSceneArgument(const py::object& sceneArgument, int views, int resolution,
                              const py::object& noise, const std::string& color, bool normals,
                              std::uint64_t seed, const std::string& mode,
                              const py::object& station, const py::object& airborne) {
    ScannerSettings settings;
    const std::optional<ScannerSettings::Mode> scannerMode = parseScannerMode(mode);
    if (!scannerMode) {
        throw py::value_error(fmt::format("mode '{}' is not object, station or airborne", mode));
    }
    settings.mode = *scannerMode;
    // The scanner settings' JSON form (as `subscan scan --settings` reads it).
    if (!station.is_none()) {
        argumentErrors([&] { from_json(toJson(station, "station"), settings.station); });
    }
    if (!airborne.is_none()) {
        argumentErrors([&] { from_json(toJson(airborne, "airborne"), settings.airborne); });
    }
    settings.views = views;
    settings.resolution = resolution;
    settings.normals = normals;
    settings.seed = seed;
    const std::string noiseText = py::isinstance<py::str>(noise)
                                      ? noise.cast<std::string>()
                                      : fmt::format("{:.17g}", noise.cast<double>());
    const std::optional<NoiseAmount> amount = parseNoiseAmount(noiseText);
    if (!amount) {
        throw py::value_error(fmt::format(
            "noise '{}' must be a distance >= 0 in metres, or in scan spacings with an h suffix "
            "(e.g. 0.0002 or '0.1h')",
            noiseText));
    }
    settings.noise = amount->value;
    settings.noiseInSpacingUnits = amount->inSpacingUnits;
    if (color != "auto" && !parseColorMode(color)) {
        throw py::value_error(fmt::format("color '{}' is not auto, none, scene or marble", color));
    }
    argumentErrors([&] { validate(settings); });

    std::unique_ptr<Scene> scene;
    bool sceneColors = false;
    if (py::isinstance<py::str>(sceneArgument) &&
        std::string_view(sceneArgument.cast<std::string>()).starts_with(kSynthetic)) {
        const std::string source = sceneArgument.cast<std::string>();
        const std::string name = source.substr(kSynthetic.size());
        scene = argumentErrors([&] {
            try {
                return makeBuiltInScene(name);
            } catch (const Error& error) {
                throw Error(fmt::format("{}: {}", source, error.what()));
            }
        });
        sceneColors = true;
    } else {
        const CloudHandle mesh = meshArgument(sceneArgument, "scan");
        scene = makeMeshScene(mesh->cloud(), AlbedoSource::VertexColors);
        sceneColors = mesh->cloud().hasColors();
    }
    // As the CLI: plain grey from a mesh without colours would only pretend to be data.
    settings.color = color == "auto" ? (sceneColors ? ScannerSettings::Color::Scene
                                                    : ScannerSettings::Color::None)
                                     : *parseColorMode(color);
    PointCloud cloud;
    {
        const py::gil_scoped_release release;
        cloud = scanScene(*scene, settings);
    }
    return std::make_shared<CloudData>(std::move(cloud), "scan");
}

/// `subscan eval MESH [options] --json` (with temporal, `--temporal`).
py::object evaluateMesh(const py::object& meshArgumentObject, const py::object& pointsArgument,
                        int views, int width, int height, std::optional<double> distance,
                        const py::object& settingsObject, bool temporal, int frames, double step,
                        bool software) {
    checkRange(views, 1, 360, "views");
    checkRange(width, 16, 8192, "width");
    checkRange(height, 16, 8192, "height");
    checkRange(frames, 2, 10000, "frames");
    checkRange(step, 0.0, 90.0, "step");
    if (distance && !(*distance > 0.0 && std::isfinite(*distance))) {
        throw py::value_error(fmt::format("distance {} must be positive", *distance));
    }
    const RenderSettings render = settingsArgument(settingsObject);
    EvaluationSettings evaluation;
    evaluation.views = views;
    evaluation.width = width;
    evaluation.height = height;
    evaluation.distance = distance;
    TemporalEvaluationSettings temporalEvaluation;
    temporalEvaluation.frames = frames;
    temporalEvaluation.stepDegrees = step;

    std::unique_ptr<Scene> truth;
    PointCloud points;
    if (py::isinstance<py::str>(meshArgumentObject) &&
        std::string_view(meshArgumentObject.cast<std::string>()).starts_with(kSynthetic)) {
        const std::string source = meshArgumentObject.cast<std::string>();
        const std::string spec = source.substr(kSynthetic.size());
        argumentErrors([&] {
            try {
                SyntheticSource synthetic = makeSyntheticSource(spec);
                truth = std::move(synthetic.scene);
                points = std::move(synthetic.points);
                // The truth's normals: the reconstruction estimates its own (as `subscan eval`).
                points.normals.clear();
                adaptToScanner(evaluation, *truth, synthetic.scanner);
            } catch (const Error& error) {
                throw Error(fmt::format("{}: {}", source, error.what()));
            }
        });
    } else {
        const CloudHandle mesh = meshArgument(meshArgumentObject, "evaluate");
        truth = makeMeshScene(mesh->cloud(), AlbedoSource::Grey);
        const bool named = py::isinstance<py::str>(pointsArgument);
        const std::string kind = named ? pointsArgument.cast<std::string>() : "";
        if (kind == "scan") {
            ScannerSettings scanner;
            scanner.noise = 0.1;
            scanner.noiseInSpacingUnits = true;
            const py::gil_scoped_release release;
            points = scanScene(*truth, scanner);
        } else {
            // The mesh's vertices, or a scan in the mesh's frame (a Cloud or a file).
            if (kind == "vertices") {
                points = mesh->cloud();
            } else if (py::isinstance<CloudData>(pointsArgument)) {
                points = pointsArgument.cast<const CloudData&>().cloud();
            } else {
                const std::string source = pathArgument(pointsArgument);
                LoadedScan loaded;
                {
                    const py::gil_scoped_release release;
                    loaded = loadScan(source);
                }
                warnAll(source, loaded.warnings);
                points = std::move(loaded.cloud);
            }
            points.triangles.clear();
            points.normals.clear();
            points.intensities.clear();
            points.colors.assign(points.size(), srgb8Color(glm::vec3(kMeshAlbedo)));
        }
    }

    nlohmann::json report;
    {
        const py::gil_scoped_release release;
        HeadlessContextOptions options;
        options.preferHardware = !software;
        options.debugOutput = glDebugOutputRequested();
        const std::unique_ptr<GlContext> context = createHeadlessContext(options);
        if (temporal) {
            report = toJson(
                evaluateTemporal(*context, *truth, points, evaluation, temporalEvaluation, render));
        } else {
            report = toJson(evaluate(*context, *truth, points, evaluation, render));
        }
        context->throwOnErrors("while evaluating");
    }
    return toPython(report);
}

}  // namespace

void bindAnalysis(py::module_& module) {
    module.def("materials", &materials, R"doc(
The material library as `subscan materials --json` lists it: a list of dicts with name,
description, eta, sigma_s_prime, sigma_a, rd (RGB lists in mm⁻¹, or None), cumulative and
gaussians ([{variance_mm2, weight: [R, G, B]}]).
)doc");
    module.def("fit_profile", &fitProfile, py::arg("material"), py::arg("gaussians"),
               py::arg("profile") = "dipole", R"doc(
Fits `gaussians` (1..12) Gaussians to a measured material's diffusion profile ('dipole' or
'burley'), as `subscan fit-profile --json`: {material, gaussians, fit_error, r_max_mm}.
ValueError for an unknown material or one without measured coefficients.
)doc");
    module.def("scan", &scanSceneArgument, py::arg("scene"), py::kw_only(), py::arg("views") = 8,
               py::arg("resolution") = 512, py::arg("noise") = 0.0, py::arg("color") = "auto",
               py::arg("normals") = false, py::arg("seed") = 1, py::arg("mode") = "object",
               py::arg("station") = py::none(), py::arg("airborne") = py::none(), R"doc(
The virtual scanner (`subscan scan`): a Cloud scanned from `scene`, which is 'synthetic:NAME', a
mesh file, or a Cloud with triangles. views: scanner positions; resolution: rays per side of
each view; noise: range noise in metres (a number) or in scan spacings ('0.1h'); color:
'auto', 'none', 'scene' or 'marble'; normals: keep true normals. mode: 'object' (the
structured-light scanner around the object), 'station' (one terrestrial LiDAR station) or
'airborne' (one airborne strip); station and airborne: their settings as the scanner settings'
JSON names them, e.g. station={'position': [0, 1.5, 0], 'azimuth_steps': 900}.
)doc");
    module.def("evaluate", &evaluateMesh, py::arg("mesh"), py::kw_only(),
               py::arg("points") = "vertices", py::arg("views") = 8, py::arg("width") = 1024,
               py::arg("height") = 1024, py::arg("distance") = py::none(),
               py::arg("settings") = py::none(), py::arg("temporal") = false,
               py::arg("frames") = 24, py::arg("step") = 1.0, py::arg("software") = false,
               R"doc(
Reconstruction quality against ground truth, as `subscan eval --json` (DESIGN.md §7): `mesh` is
'synthetic:NAME' (the analytic scene and its virtual scan), a mesh file or a Cloud with
triangles; `points` is 'vertices' (the mesh's own), 'scan' (a virtual scan of it), or a scan in
the mesh's frame (a file or a Cloud). Returns the report as a dict ({"views", "width",
"height", "points", "spacing", "methods": {...}}); temporal=True measures stability along
`frames` frames `step` degrees apart instead (`eval --temporal`). Uses its own GL context.
)doc");
}

}  // namespace subscan::python
