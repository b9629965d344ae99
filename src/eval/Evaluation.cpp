#include "eval/Evaluation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "core/Parallel.h"
#include "eval/GroundTruth.h"
#include "gpu/ShaderSources.h"
#include "io/Image.h"
#include "io/PointRecordSource.h"
#include "io/TemporaryFolder.h"
#include "lod/CopcWriter.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "render/FrameUniforms.h"
#include "render/PresentPass.h"
#include "render/ReducedResolution.h"
#include "render/Renderer.h"
#include "render/ShadePass.h"

namespace subscan {

namespace {

/// Runs the pipeline's own Shade and Present passes on images that did not come from it (the
/// ground truth, the flat-shaded baselines), so every method is lit by the same code.
class ImageShader {
  public:
    ImageShader(GlContext& context, const GpuPointCloud& cloud)
        : context_(context),
          cloud_(cloud),
          shade_(sources_, ShadeOutputs::Radiance),
          present_(sources_, "radiance", PresentBackground::WhereNoDepth, "surfaceDepth") {}

    std::vector<std::uint8_t> shade(const Camera& camera, const RenderSettings& settings,
                                    const std::vector<float>& depth,
                                    const std::vector<glm::vec3>& normals,
                                    const std::vector<glm::vec3>& albedo) {
        const gpu::PyramidLayout& layout = uniforms_.update(camera, settings, 1.0, cloud_);
        const int w = camera.width, h = camera.height;
        std::vector<float> rgba(depth.size() * 4);
        auto upload = [&](const char* name, const std::vector<glm::vec3>& values) {
            for (std::size_t i = 0; i < values.size(); ++i) {
                rgba[4 * i] = values[i].x;
                rgba[4 * i + 1] = values[i].y;
                rgba[4 * i + 2] = values[i].z;
                rgba[4 * i + 3] = 1.0f;
            }
            resources_.ensureTexture(name, TextureFormat::RGBA16F, w, h).uploadFloats(rgba);
        };
        resources_.ensureTexture("surfaceDepth", TextureFormat::R32F, w, h).uploadFloats(depth);
        upload("normals", normals);
        upload("filledColor", albedo);
        FrameContext frame{camera,     cloud_,  settings, context_.capabilities(),
                           resources_, clears_, layout,   1.0};
        shade_.execute(frame);
        present_.execute(frame);
        return resources_.texture("image").readRgba8();
    }

  private:
    GlContext& context_;
    const GpuPointCloud& cloud_;
    ShaderSources sources_;
    FrameUniforms uniforms_;
    FrameResources resources_;
    GpuClear clears_{sources_, context_.capabilities()};
    ShadePass shade_;
    PresentPass present_;
};

std::vector<glm::vec3> rgbOf(const std::vector<float>& rgba) {
    std::vector<glm::vec3> rgb(rgba.size() / 4);
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        rgb[i] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]};
    }
    return rgb;
}

/// The last frame's pipeline image `name` of `channels` floats per texel at the output camera's
/// pixels: each takes the texel its centre falls in (ReducedResolution.h), as the metrics
/// compare pixel by pixel.
std::vector<float> atOutputPixels(const Renderer& renderer, const char* name, int channels,
                                  const Camera& output) {
    const std::vector<float> values = renderer.resources().texture(name).readFloats();
    const Camera& pipeline = renderer.pipelineCamera();
    const int divisor = renderer.pipelineDivisor();
    if (divisor == 1) {
        return values;
    }
    std::vector<float> resampled;
    resampled.reserve(static_cast<std::size_t>(output.width * output.height * channels));
    for (int y = 0; y < output.height; ++y) {
        for (int x = 0; x < output.width; ++x) {
            const glm::ivec2 texel =
                glm::clamp(glm::ivec2(glm::floor(reducedPosition(output, pipeline, divisor,
                                                                 glm::dvec2(x + 0.5, y + 0.5)))),
                           glm::ivec2(0), glm::ivec2(pipeline.width - 1, pipeline.height - 1));
            const auto first = values.begin() + (texel.y * pipeline.width + texel.x) * channels;
            resampled.insert(resampled.end(), first, first + channels);
        }
    }
    return resampled;
}

/// Normals that face the eye, for flat shading of methods without normals.
std::vector<glm::vec3> towardsEye(const Camera& camera) {
    std::vector<glm::vec3> normals(static_cast<std::size_t>(camera.width * camera.height));
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            normals[static_cast<std::size_t>(y * camera.width + x)] =
                glm::vec3(-glm::normalize(pixelCentreDirection(camera, x, y)));
        }
    }
    return normals;
}

/// A baseline's frame: the rasterized points (`mode`, `pointSize`), flat shaded by `shader`.
struct BaselineFrame {
    std::vector<std::uint8_t> image;
    ReconstructionImages images;
};

BaselineFrame renderBaseline(Renderer& renderer, ImageShader& shader, const Camera& camera,
                             const RenderSettings& render, RenderMode mode, float pointSize) {
    RenderSettings settings = render;
    settings.raster.mode = mode;
    settings.raster.stage = Stage::Final;
    settings.raster.pointSize = pointSize;
    renderer.render(camera, settings);
    ReconstructionImages images{renderer.resources().texture("depth").readFloats(), {}};
    const std::vector<glm::vec3> albedo = rgbOf(renderer.resources().texture("color").readFloats());
    return {shader.shade(camera, render, images.depth, towardsEye(camera), albedo),
            std::move(images)};
}

/// The per-view pictures of EvaluationSettings::exportDirectory.
void exportView(const std::filesystem::path& directory, int view, const Camera& camera,
                double spacing, const GroundTruthImages& truth, const ReconstructionImages& surface,
                const std::vector<std::uint8_t>& truthImage,
                const std::vector<std::uint8_t>& surfaceImage) {
    std::filesystem::create_directories(directory);
    const int w = camera.width, h = camera.height;
    const auto name = [&](const char* what) {
        return directory / fmt::format("view{}_{}.png", view, what);
    };
    writePng(name("truth"), {w, h, 4, truthImage});
    writePng(name("surface"), {w, h, 4, surfaceImage});
    Image8 coverage{w, h, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h * 3), 0)};
    Image8 normalError{w, h, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h), 0)};
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        const bool inTruth = std::isfinite(truth.depth[i]);
        const bool inSurface = std::isfinite(surface.depth[i]);
        const bool unsampled = inTruth && !truth.sampled.empty() && truth.sampled[i] == 0;
        const bool occluded =
            inTruth && inSurface && showsThrough(truth, i, surface.depth[i], spacing);
        const glm::u8vec3 color = unsampled              ? glm::u8vec3(60)
                                  : occluded             ? glm::u8vec3(250, 220, 30)
                                  : inTruth && inSurface ? glm::u8vec3(160)
                                  : inTruth              ? glm::u8vec3(230, 40, 40)
                                  : inSurface            ? glm::u8vec3(40, 80, 230)
                                                         : glm::u8vec3(0);
        for (int c = 0; c < 3; ++c) {
            coverage.pixels[3 * i + static_cast<std::size_t>(c)] = color[c];
        }
        if (inTruth && inSurface) {
            const double cosine = std::clamp(
                static_cast<double>(glm::dot(glm::normalize(surface.normals[i]), truth.normals[i])),
                -1.0, 1.0);
            const double degrees = std::acos(cosine) * 180.0 / std::numbers::pi;
            normalError.pixels[i] =
                static_cast<std::uint8_t>(std::lround(std::min(degrees, 45.0) / 45.0 * 255.0));
        }
    }
    writePng(name("coverage"), coverage);
    writePng(name("normal_error"), normalError);
}

}  // namespace

SpacingAtTruth::SpacingAtTruth(const PointCloud& points, const PointSpacing& spacing)
    : points_(points),
      spacing_(spacing),
      adaptor_{points.positions},
      tree_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}

std::vector<float> SpacingAtTruth::at(const Camera& camera, const GroundTruthImages& truth) const {
    std::vector<float> spacing(truth.depth.size(), static_cast<float>(spacing_.global));
    if (spacing_.local.empty() || points_.positions.empty()) {
        return spacing;
    }
    const glm::dmat4 worldFromView = glm::inverse(camera.view);
    const auto width = static_cast<std::size_t>(camera.width);
    inParallel(truth.depth.size(), [&](std::size_t i) {
        if (!std::isfinite(truth.depth[i])) {
            return;
        }
        const glm::dvec3 inView =
            static_cast<double>(truth.depth[i]) *
            pixelCentreDirection(camera, static_cast<int>(i % width), static_cast<int>(i / width));
        const glm::vec3 query(glm::dvec3(worldFromView * glm::dvec4(inView, 1.0)) - points_.origin);
        std::uint32_t nearest = 0;
        float squared = 0.0f;
        if (tree_.knnSearch(&query.x, 1, &nearest, &squared) == 0) {
            return;
        }
        const glm::vec4& local = spacing_.local[nearest];
        spacing[i] =
            static_cast<float>(spacing_.global * std::max(local.w, glm::length(glm::vec3(local))));
    });
    return spacing;
}

/// The points of an evaluation indexed as a streamed survey: a COPC file in a temporary folder
/// of its own, removed with it.
class StreamedPoints {
  public:
    explicit StreamedPoints(const PointCloud& points)
        : folder_(std::filesystem::temp_directory_path(), "subscan-eval") {
        const std::unique_ptr<PointRecordSource> records =
            cloudRecordSource(points, "the evaluated points");
        lod::IndexSettings index;
        index.temporaryDirectory = folder_.path();
        lod::writeCopc(*records, folder_.path() / "points.copc.laz", index);
        source_ = lod::openCopc(folder_.path() / "points.copc.laz");
    }

    const lod::NodeSource& source() const { return *source_; }

  private:
    TemporaryFolder folder_;
    std::unique_ptr<lod::NodeSource> source_;  // declared after the folder: closed before it goes
};

/// The nodes a view selects (or several views: one set for all), with the spacing and normals
/// `render` gives a streamed view and a renderer of their own.
struct StreamedView {
    StreamedView(GlContext& context, const StreamedPoints& points, std::span<const Camera> cameras,
                 std::uint64_t budget, NormalSource requested)
        : scan(lod::loadStreamedScan(points.source(),
                                     lod::selectNodes(points.source(), cameras, budget))),
          spacing(estimatePointSpacing(scan.cloud, scan.levelSpacing)),
          normals(normalsFor(scan.cloud, streamedNormals(requested))),
          renderer(std::make_unique<Renderer>(context, scan.cloud, spacing)) {
        if (!normals.empty()) {
            renderer->setPointNormals(normals);
        }
    }
    LoadedScan scan;
    PointSpacing spacing;
    std::vector<glm::vec3> normals;  // empty where none are estimated
    std::unique_ptr<Renderer> renderer;
};

EvaluationReport evaluate(GlContext& context, const Scene& truth, const PointCloud& points,
                          const EvaluationSettings& settings, const RenderSettings& render) {
    const PointSpacing pointSpacing = estimatePointSpacing(points);
    Renderer renderer(context, points, pointSpacing);
    renderer.prepareNormals(points, render.surface.normals);
    ImageShader shader(context, renderer.gpuCloud());
    const double h = renderer.spacing();
    std::optional<SpacingAtTruth> spacingAtTruth;
    if (settings.occlusionsByLocalSpacing) {
        spacingAtTruth.emplace(points, pointSpacing);
    }

    // A streamed survey: the points as a COPC file, each view's nodes loaded into a renderer
    // of their own.
    std::optional<StreamedPoints> streamed;
    if (settings.pointBudget) {
        streamed.emplace(points);
    }

    EvaluationReport report;
    std::vector<QualityMetrics> pointViews, surfaceViews;
    std::vector<std::vector<QualityMetrics>> splatViews(
        static_cast<std::size_t>(settings.largestSplat - settings.smallestSplat + 1));
    const int views =
        settings.viewpoints.empty() ? settings.views : static_cast<int>(settings.viewpoints.size());
    for (int view = 0; view < views; ++view) {
        OrbitView orbit;
        if (settings.viewpoints.empty()) {
            orbit.yawDegrees = 20.0 + 360.0 * view / settings.views;
            orbit.pitchDegrees = view % 2 == 0 ? 25.0 : -15.0;
            orbit.distance = settings.distance;
        } else {
            orbit = settings.viewpoints[static_cast<std::size_t>(view)];
        }
        const Camera camera = orbitCamera(truth.bounds(), orbit, settings.width, settings.height,
                                          settings.fovyDegrees);
        GroundTruthImages groundTruth = renderGroundTruth(truth, camera, settings.sampled);
        if (spacingAtTruth) {
            groundTruth.spacing = spacingAtTruth->at(camera, groundTruth);
        }
        const std::vector<std::uint8_t> truthImage = shader.shade(
            camera, render, groundTruth.depth, groundTruth.normals, groundTruth.albedo);
        // The baselines: rasterized points, flat shaded.
        auto baseline = [&](RenderMode mode, float pointSize) {
            const BaselineFrame frame =
                renderBaseline(renderer, shader, camera, render, mode, pointSize);
            QualityMetrics metrics = compareToGroundTruth(frame.images, groundTruth, h);
            metrics.psnrDb = psnr(frame.image, truthImage);
            return metrics;
        };
        pointViews.push_back(baseline(RenderMode::Points, 1.0f));
        for (int size = settings.smallestSplat; size <= settings.largestSplat; ++size) {
            splatViews[static_cast<std::size_t>(size - settings.smallestSplat)].push_back(
                baseline(RenderMode::Splats, static_cast<float>(size)));
        }

        RenderSettings surfaceSettings = render;
        surfaceSettings.raster.mode = RenderMode::Surface;
        surfaceSettings.raster.stage = Stage::Final;
        surfaceSettings.temporal.enabled = false;  // one frame per view (eval --temporal has it)
        std::optional<StreamedView> streamedView;
        if (streamed) {
            streamedView.emplace(context, *streamed, std::span(&camera, 1), *settings.pointBudget,
                                 render.surface.normals);
            report.surfacePoints += static_cast<double>(streamedView->scan.cloud.size()) / views;
        }
        Renderer& surfaceRenderer = streamedView ? *streamedView->renderer : renderer;
        const int divisor =
            surfaceRenderer.render(camera, surfaceSettings, FrameOutputs::Everything).divisor;
        report.surfaceReducedViews += divisor == 1 ? 0 : 1;
        ReconstructionImages images{atOutputPixels(surfaceRenderer, "surfaceDepth", 1, camera),
                                    rgbOf(atOutputPixels(surfaceRenderer, "normals", 4, camera))};
        QualityMetrics metrics = compareToGroundTruth(images, groundTruth, h);
        const std::vector<std::uint8_t> surfaceImage = surfaceRenderer.readImage();
        metrics.psnrDb = psnr(surfaceImage, truthImage);
        surfaceViews.push_back(metrics);
        if (!settings.exportDirectory.empty()) {
            exportView(settings.exportDirectory, view, camera, h, groundTruth, images, truthImage,
                       surfaceImage);
        }
    }

    report.views = views;
    report.width = settings.width;
    report.height = settings.height;
    report.points = points.size();
    report.spacing = h;
    report.points1px = average(pointViews);
    report.surface = average(surfaceViews);
    for (std::size_t i = 0; i < splatViews.size(); ++i) {
        const QualityMetrics candidate = average(splatViews[i]);
        if (report.splatSize == 0 || candidate.psnrDb > report.splats.psnrDb) {
            report.splats = candidate;
            report.splatSize = settings.smallestSplat + static_cast<int>(i);
        }
    }
    return report;
}

namespace {

/// 1 where `depth` is finite.
std::vector<std::uint8_t> maskOf(const std::vector<float>& depth) {
    std::vector<std::uint8_t> mask(depth.size());
    std::transform(depth.begin(), depth.end(), mask.begin(),
                   [](float d) { return std::isfinite(d) ? 1 : 0; });
    return mask;
}

/// The truth seen through `camera` with `factor` x `factor` rays per pixel, shaded like the
/// methods: the picture averaged in linear light, covered where most of a pixel's rays hit.
SequenceFrame supersampledTruth(const Scene& truth, ImageShader& shader, const Camera& camera,
                                const RenderSettings& render, int factor) {
    Camera fine = camera;
    fine.width = camera.width * factor;
    fine.height = camera.height * factor;
    const GroundTruthImages images = renderGroundTruth(truth, fine);
    const std::vector<std::uint8_t> picture =
        shader.shade(fine, render, images.depth, images.normals, images.albedo);
    SequenceFrame frame{
        downsampleSrgb(picture, camera.width, camera.height, factor),
        std::vector<std::uint8_t>(static_cast<std::size_t>(camera.width * camera.height), 0)};
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            int hits = 0;
            for (int sy = 0; sy < factor; ++sy) {
                for (int sx = 0; sx < factor; ++sx) {
                    hits += std::isfinite(
                        images.depth[(y * factor + sy) * fine.width + x * factor + sx]);
                }
            }
            frame.mask[y * camera.width + x] = 2 * hits >= factor * factor ? 1 : 0;
        }
    }
    return frame;
}

}  // namespace

TemporalReport evaluateTemporal(GlContext& context, const Scene& truth, const PointCloud& points,
                                const EvaluationSettings& settings,
                                const TemporalEvaluationSettings& temporal,
                                const RenderSettings& render) {
    std::vector<Camera> cameras;
    for (int t = 0; t < temporal.frames; ++t) {
        OrbitView orbit;
        if (settings.scannerView) {
            orbit = settings.scannerView(t * temporal.stepDegrees);
        } else {
            orbit.yawDegrees = 20.0 + t * temporal.stepDegrees;
            orbit.pitchDegrees = 25.0;
            orbit.distance = settings.distance;
        }
        cameras.push_back(orbitCamera(truth.bounds(), orbit, settings.width, settings.height,
                                      settings.fovyDegrees));
    }
    const PointSpacing spacing = estimatePointSpacing(points);
    Renderer renderer(context, points, spacing);  // the baselines' (and the surface's, whole)
    std::optional<StreamedView> streamed;
    if (settings.pointBudget) {
        streamed.emplace(context, StreamedPoints(points), cameras, *settings.pointBudget,
                         render.surface.normals);
    }
    const PointCloud& surfacePoints = streamed ? streamed->scan.cloud : points;
    const PointSpacing& surfaceSpacing = streamed ? streamed->spacing : spacing;
    Renderer& surfaceRenderer = streamed ? *streamed->renderer : renderer;
    // Their own renderers, so the filter's histories run on undisturbed by the other methods.
    Renderer filtered(context, surfacePoints, surfaceSpacing);
    Renderer converged(context, surfacePoints, surfaceSpacing);
    const std::vector<glm::vec3> normals =
        streamed ? streamed->normals : normalsFor(points, render.surface.normals);
    if (!normals.empty()) {
        for (Renderer* each : {&surfaceRenderer, &filtered, &converged}) {
            each->setPointNormals(normals);
        }
    }
    ImageShader shader(context, renderer.gpuCloud());
    RenderSettings surfaceSettings = render;
    surfaceSettings.raster.mode = RenderMode::Surface;
    surfaceSettings.raster.stage = Stage::Final;
    surfaceSettings.temporal.enabled = false;
    RenderSettings filteredSettings = surfaceSettings;
    filteredSettings.temporal.enabled = true;

    TemporalReport report;
    std::vector<SequenceFrame> truthFrames, pointFrames, splatFrames, surfaceFrames, filteredFrames,
        convergedFrames;
    // The filter's picture, its mask where the history's coverage reaches a half.
    auto filteredFrame = [](Renderer& withFilter, const Camera& camera) {
        const std::vector<float> coverage = atOutputPixels(withFilter, "history", 4, camera);
        SequenceFrame frame{withFilter.readImage(), {}};
        for (std::size_t i = 3; i < coverage.size(); i += 4) {
            frame.mask.push_back(coverage[i] >= 0.5f ? 1 : 0);
        }
        return frame;
    };
    for (int t = 0; t < temporal.frames; ++t) {
        const Camera& camera = cameras[static_cast<std::size_t>(t)];
        truthFrames.push_back(
            supersampledTruth(truth, shader, camera, render, temporal.supersampling));

        for (const auto& [mode, size, frames] :
             {std::tuple{RenderMode::Points, 1.0f, &pointFrames},
              std::tuple{RenderMode::Splats, render.raster.pointSize, &splatFrames}}) {
            BaselineFrame frame = renderBaseline(renderer, shader, camera, render, mode, size);
            frames->push_back({std::move(frame.image), maskOf(frame.images.depth)});
        }

        surfaceRenderer.render(camera, surfaceSettings, FrameOutputs::Everything);
        surfaceFrames.push_back(
            {surfaceRenderer.readImage(),
             maskOf(atOutputPixels(surfaceRenderer, "surfaceDepth", 1, camera))});

        // The filtered sequence starts converged at the first pose, then follows the orbit.
        for (int still = 0; still < (t == 0 ? temporal.stillSamples : 1); ++still) {
            filtered.render(camera, filteredSettings);
        }
        filteredFrames.push_back(filteredFrame(filtered, camera));

        converged.restartTemporalFilter();
        for (int still = 0; still < temporal.stillSamples; ++still) {
            converged.render(camera, filteredSettings);
        }
        convergedFrames.push_back(filteredFrame(converged, camera));
        if (!settings.exportDirectory.empty()) {
            std::filesystem::create_directories(settings.exportDirectory);
            for (const auto& [name, frames] :
                 {std::pair{"truth", &truthFrames}, std::pair{"points", &pointFrames},
                  std::pair{"surface", &surfaceFrames}, std::pair{"temporal", &filteredFrames},
                  std::pair{"supersampled", &convergedFrames}}) {
                writePng(settings.exportDirectory / fmt::format("frame{:04}_{}.png", t, name),
                         {camera.width, camera.height, 4, frames->back().image});
            }
        }
        if (t == 0) {
            report.stillPsnrSurfaceDb = psnr(surfaceFrames[0].image, truthFrames[0].image);
            report.stillPsnrTemporalDb = psnr(filteredFrames[0].image, truthFrames[0].image);
        }
    }
    report.frames = temporal.frames;
    report.stepDegrees = temporal.stepDegrees;
    report.width = settings.width;
    report.height = settings.height;
    report.supersampling = temporal.supersampling;
    report.points = points.size();
    report.spacing = renderer.spacing();
    report.surfacePoints = surfacePoints.size();
    report.splatSize = render.raster.pointSize;
    report.points1px = compareSequences(pointFrames, truthFrames);
    report.splats = compareSequences(splatFrames, truthFrames);
    report.surface = compareSequences(surfaceFrames, truthFrames);
    report.surfaceTemporal = compareSequences(filteredFrames, truthFrames);
    report.surfaceSupersampled = compareSequences(convergedFrames, truthFrames);
    return report;
}

nlohmann::json toJson(const TemporalReport& report) {
    auto method = [](const TemporalMetrics& m) {
        return nlohmann::json{{"temporal_error", m.temporalError},
                              {"mask_flicker", m.maskFlicker},
                              {"psnr_db", m.psnrDb}};
    };
    nlohmann::json splats = method(report.splats);
    splats["point_size"] = report.splatSize;
    nlohmann::json surface = method(report.surface);
    surface["still_psnr_db"] = report.stillPsnrSurfaceDb;
    nlohmann::json filtered = method(report.surfaceTemporal);
    filtered["still_psnr_db"] = report.stillPsnrTemporalDb;
    return {
        {"frames", report.frames},
        {"step_degrees", report.stepDegrees},
        {"width", report.width},
        {"height", report.height},
        {"supersampling", report.supersampling},
        {"points", report.points},
        {"spacing", report.spacing},
        {"surface_points", report.surfacePoints},
        {"methods",
         {{"points", method(report.points1px)},
          {"splats", splats},
          {"surface", surface},
          {"surface_temporal", filtered},
          {"surface_supersampled", method(report.surfaceSupersampled)}}},
    };
}

nlohmann::json toJson(const EvaluationReport& report) {
    auto method = [](const QualityMetrics& m) {
        nlohmann::json json = {
            {"coverage", m.coverage},
            {"leakage", m.leakage},
            {"depth_error_median_h", m.depthErrorMedianH},
            {"depth_bias_h", m.depthBiasH},
            {"occlusion_error_rate", m.occlusionErrorRate},
            {"normal_error_mean_deg", nullptr},
            {"normal_error_p95_deg", nullptr},
            {"psnr_db", m.psnrDb},
        };
        if (m.normalErrorMeanDeg) {
            json["normal_error_mean_deg"] = *m.normalErrorMeanDeg;
            json["normal_error_p95_deg"] = *m.normalErrorP95Deg;
        }
        return json;
    };
    nlohmann::json splats = method(report.splats);
    splats["point_size"] = report.splatSize;
    return {
        {"views", report.views},
        {"width", report.width},
        {"height", report.height},
        {"points", report.points},
        {"spacing", report.spacing},
        {"surface_reduced_views", report.surfaceReducedViews},
        {"surface_points", report.surfacePoints},
        {"methods",
         {{"points", method(report.points1px)},
          {"splats", splats},
          {"surface", method(report.surface)}}},
    };
}

namespace {

/// The orbit (Y up, as the built-in scenes) that puts the eye at `eye` looking at `target`.
OrbitView lookingAt(const glm::dvec3& eye, const glm::dvec3& target) {
    const glm::dvec2 angles = orbitAngles(eye - target, UpAxis::Y);
    OrbitView orbit;
    orbit.center = target;
    orbit.distance = glm::length(eye - target);
    orbit.yawDegrees = angles.x;
    orbit.pitchDegrees = angles.y;
    return orbit;
}

}  // namespace

void adaptToScanner(EvaluationSettings& settings, const Scene& scene,
                    const ScannerSettings& scanner, ViewsFrom viewsFrom) {
    if (scanner.mode == ScannerSettings::Mode::Object) {
        return;
    }
    constexpr double kFirstAzimuthDegrees = 45.0;
    ScannerSettings fixed = scanner;
    const auto orbitAt = [distance = settings.distance](double pitchDegrees) {
        return [distance, pitchDegrees](double degrees) {
            OrbitView orbit;
            orbit.yawDegrees = kFirstAzimuthDegrees + degrees;
            orbit.pitchDegrees = pitchDegrees;
            orbit.distance = distance;
            return orbit;
        };
    };
    if (scanner.mode == ScannerSettings::Mode::Station) {
        fixed.station.position = stationPosition(scene, scanner.station);  // once, not per pixel
    }
    if (viewsFrom == ViewsFrom::Orbit) {
        settings.scannerView = orbitAt(30.0);
    } else if (scanner.mode == ScannerSettings::Mode::Station) {
        settings.scannerView = [station = *fixed.station.position](double degrees) {
            constexpr double kAbove = 1.0, kBehind = 1.0, kLookDistance = 20.0, kDownDegrees = 10.0;
            const double azimuth = glm::radians(kFirstAzimuthDegrees + degrees);
            const glm::dvec3 outward(std::sin(azimuth), 0.0, std::cos(azimuth));
            const glm::dvec3 eye = station + glm::dvec3(0.0, kAbove, 0.0) - kBehind * outward;
            const double down = glm::radians(kDownDegrees);
            const glm::dvec3 target = eye + kLookDistance * (std::cos(down) * outward +
                                                             glm::dvec3(0.0, -std::sin(down), 0.0));
            return lookingAt(eye, target);
        };
    } else {
        settings.scannerView = orbitAt(45.0);
    }
    settings.viewpoints.clear();
    for (int view = 0; view < settings.views; ++view) {
        settings.viewpoints.push_back(settings.scannerView(360.0 * view / settings.views));
    }
    settings.sampled = [&scene, fixed](const glm::dvec3& p, const glm::dvec3& normal) {
        return scannerCanSample(scene, fixed, p, normal);
    };
    settings.occlusionsByLocalSpacing = true;
}

}  // namespace subscan
