#include <memory>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/cli/CommandSupport.h"
#include "app/cli/Commands.h"
#include "core/Error.h"
#include "core/Srgb.h"
#include "eval/Evaluation.h"
#include "gpu/GlContext.h"
#include "scan/Scene.h"
#include "scan/SyntheticScenes.h"
#include "scan/VirtualScanner.h"

namespace subscan::cli {

namespace {

struct EvalOptions {
    std::string source;
    EvaluationSettings evaluation;
    bool temporal = false;
    TemporalEvaluationSettings temporalEvaluation;
    std::string points = "vertices";
    std::string viewsFrom = "scanner";
    std::string settingsFile;
    bool json = false;
    bool software = false;
};

/// The albedo the ground truth of a mesh shows, given to its points too so that PSNR compares
/// geometry and shading, not a colour convention.
constexpr float kMeshAlbedo = 0.7f;

int runEval(const EvalOptions& options) {
    RenderSettings render;
    if (!options.settingsFile.empty()) {
        render = readSettingsFile(options.settingsFile);
    }
    std::unique_ptr<Scene> truth;
    PointCloud points;
    ScannerSettings scanner;
    constexpr std::string_view kSynthetic = "synthetic:";
    if (std::string_view(options.source).starts_with(kSynthetic)) {
        const std::string spec = options.source.substr(kSynthetic.size());
        try {
            SyntheticSource source = makeSyntheticSource(spec);
            truth = std::move(source.scene);
            points = std::move(source.points);
            // The virtual scanner's normals are the truth's: the reconstruction must estimate
            // its own, as from a real scanner's points.
            points.normals.clear();
            scanner = source.scanner;
        } catch (const Error& error) {
            throw Error(fmt::format("{}: {}", options.source, error.what()));
        }
    } else {
        const LoadedScan mesh = loadScanForCommand(options.source);
        if (mesh.cloud.triangles.empty()) {
            throw Error(
                fmt::format("{}: has no faces; eval needs a mesh as ground truth", options.source));
        }
        truth = makeMeshScene(mesh.cloud, AlbedoSource::Grey);
        if (options.points == "scan") {
            ScannerSettings objectScan;
            objectScan.noise = 0.1;
            objectScan.noiseInSpacingUnits = true;
            points = scanScene(*truth, objectScan);
        } else {
            // The mesh's vertices, or a scan file in the mesh's frame (the range scans a mesh
            // was merged from: real noise and registration offsets, judged by the mesh).
            points = options.points == "vertices" ? mesh.cloud
                                                  : loadScanForCommand(options.points).cloud;
            points.triangles.clear();
            points.normals.clear();
            points.intensities.clear();
            points.colors.assign(points.size(), srgb8Color(glm::vec3(kMeshAlbedo)));
        }
    }

    EvaluationSettings evaluation = options.evaluation;
    adaptToScanner(evaluation, *truth, scanner,
                   options.viewsFrom == "orbit" ? ViewsFrom::Orbit : ViewsFrom::Scanner);

    HeadlessContextOptions contextOptions;
    contextOptions.preferHardware = !options.software;
    contextOptions.debugOutput = glDebugOutputRequested();
    const std::unique_ptr<GlContext> context = createHeadlessContext(contextOptions);
    if (options.temporal) {
        const TemporalReport report = evaluateTemporal(*context, *truth, points, evaluation,
                                                       options.temporalEvaluation, render);
        context->throwOnErrors("while evaluating");
        if (options.json) {
            fmt::print("{}\n", toJson(report).dump(2));
            return 0;
        }
        fmt::print(
            "{}: {} points (h = {:.4g}), {} frames of {}x{}, {}° apart, truth {}x{} rays "
            "per pixel{}\n",
            options.source, report.points, report.spacing, report.frames, report.width,
            report.height, report.stepDegrees, report.supersampling, report.supersampling,
            evaluation.pointBudget
                ? fmt::format("; the surface streamed within {} points: {} for every frame",
                              *evaluation.pointBudget, report.surfacePoints)
                : "");
        fmt::print("{:<18} {:>10} {:>12} {:>8} {:>12}\n", "method", "E_t", "mask flicker", "PSNR",
                   "still PSNR");
        auto row = [](const std::string& name, const TemporalMetrics& m, std::string still) {
            fmt::print("{:<18} {:>10.5f} {:>12.5f} {:>8.2f} {:>12}\n", name, m.temporalError,
                       m.maskFlicker, m.psnrDb, still);
        };
        row("points", report.points1px, "-");
        row(fmt::format("splats ({}px)", report.splatSize), report.splats, "-");
        row("surface", report.surface, fmt::format("{:.2f}", report.stillPsnrSurfaceDb));
        row("surface+temporal", report.surfaceTemporal,
            fmt::format("{:.2f}", report.stillPsnrTemporalDb));
        row(fmt::format("surface, {}x each", options.temporalEvaluation.stillSamples),
            report.surfaceSupersampled, "-");
        return 0;
    }
    const EvaluationReport report = evaluate(*context, *truth, points, evaluation, render);
    context->throwOnErrors("while evaluating");
    if (options.json) {
        fmt::print("{}\n", toJson(report).dump(2));
        return 0;
    }
    fmt::print("{}: {} points (h = {:.4g}), {} views of {}x{}", options.source, report.points,
               report.spacing, report.views, report.width, report.height);
    fmt::print("{}{}\n",
               report.surfaceReducedViews == 0
                   ? ""
                   : fmt::format(" ({} of them reconstructed at reduced resolution)",
                                 report.surfaceReducedViews),
               evaluation.pointBudget
                   ? fmt::format("; the surface streamed within {} points: {:.0f} a view",
                                 *evaluation.pointBudget, report.surfacePoints)
                   : "");
    fmt::print("{:<14} {:>9} {:>9} {:>10} {:>10} {:>10} {:>10} {:>10} {:>8}\n", "method",
               "coverage", "leakage", "depth/h", "bias/h", "occluded", "normal°", "normal95",
               "PSNR");
    auto row = [](const std::string& name, const QualityMetrics& m) {
        fmt::print(
            "{:<14} {:>9.4f} {:>9.4f} {:>10.3f} {:>10.3f} {:>10.4f} {:>10} {:>10} {:>8.2f}\n", name,
            m.coverage, m.leakage, m.depthErrorMedianH, m.depthBiasH, m.occlusionErrorRate,
            m.normalErrorMeanDeg ? fmt::format("{:.2f}", *m.normalErrorMeanDeg) : "-",
            m.normalErrorP95Deg ? fmt::format("{:.2f}", *m.normalErrorP95Deg) : "-", m.psnrDb);
    };
    row("points", report.points1px);
    row(fmt::format("splats ({}px)", report.splatSize), report.splats);
    row("surface", report.surface);
    return 0;
}

}  // namespace

Command addEvalCommand(CLI::App& parent) {
    auto options = std::make_shared<EvalOptions>();
    CLI::App* eval = parent.add_subcommand(
        "eval",
        "Reconstruction quality against ground truth (a mesh, or synthetic:NAME); LiDAR sources "
        "are judged from views near their scanner, over the surfaces it could sample");
    eval->add_option("mesh", options->source, "Mesh PLY with faces, or synthetic:NAME")->required();
    eval->add_option("--views", options->evaluation.views, "Views on the orbit")
        ->check(CLI::Range(1, 360));
    eval->add_option("--views-from", options->viewsFrom,
                     "Where the views of a LiDAR source stand: scanner (near the station, or "
                     "over the strip at 45 degrees) or orbit (around the whole scene, 30 degrees "
                     "down)")
        ->check(CLI::IsMember({"scanner", "orbit"}));
    eval->add_option("--width", options->evaluation.width, "Image width")
        ->check(CLI::Range(16, 8192));
    eval->add_option("--height", options->evaluation.height, "Image height")
        ->check(CLI::Range(16, 8192));
    eval->add_option("--distance", options->evaluation.distance,
                     "Eye distance from the centre (scene units), for close-ups; default frames "
                     "the scene")
        ->check(finiteNumber())
        ->check(CLI::PositiveNumber);
    eval->add_option("--points", options->points,
                     "Points of a mesh: vertices (its own), scan (a virtual scan of it), or a "
                     "scan file in the mesh's frame")
        ->check(CLI::IsMember({"vertices", "scan"}) | CLI::ExistingFile);
    eval->add_option("--settings", options->settingsFile, "Settings JSON for the surface")
        ->check(CLI::ExistingFile);
    eval->add_option("--export-views", options->evaluation.exportDirectory,
                     "Directory for per-view pictures: truth, surface, coverage, normal error");
    eval->add_flag("--temporal", options->temporal,
                   "Stability along a slow orbit instead: E_t, mask flicker and PSNR per frame "
                   "against a 4x4-supersampled truth, with and without the temporal filter");
    eval->add_option("--frames", options->temporalEvaluation.frames, "Frames of --temporal")
        ->check(CLI::Range(2, 10000));
    eval->add_option("--step", options->temporalEvaluation.stepDegrees,
                     "Degrees of yaw between frames of --temporal")
        ->check(finiteNumber())
        ->check(CLI::Range(0.0, 90.0));
    eval->add_option("--point-budget", options->evaluation.pointBudget,
                     "Reconstruct the surface as a streamed survey: the points indexed into a "
                     "COPC file in a temporary folder, each view loading the nodes it selects "
                     "within this many points")
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40));
    eval->add_flag("--json", options->json, "Machine-readable output");
    eval->add_flag("--software", options->software,
                   "Use Mesa's software rasterizer even when a GPU exists");
    return {eval, [options] { return runEval(*options); }};
}

}  // namespace subscan::cli
